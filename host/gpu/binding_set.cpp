#include "gpu/binding_set.hpp"
#include "gpu/ray_packets.hpp"

#include <algorithm>
#include <string>

#include "core/errors.hpp"
#include "gpu/buffer_arena.hpp"

namespace dacrt::gpu {

namespace {

std::uint64_t stackBytes(std::uint32_t maxDepth) { return (2 * std::uint64_t(maxDepth) + 1) * sizeof(StackEntry); }

bool isAddressed(std::uint32_t binding) {
    return std::find(kAddressedBindings.begin(), kAddressedBindings.end(), binding) != kAddressedBindings.end();
}

std::uint64_t chunksOf(const PlannedBuffer& b) {
    const std::uint64_t bytes = std::max<std::uint64_t>(b.bytes, 16);  // as Buffer allocates it
    return b.chunkBytes ? (bytes + b.chunkBytes - 1) / b.chunkBytes : 1;
}

std::uint64_t chunkTableBytes(std::uint64_t chunks) { return DACRT_CHUNK_TABLE_ADDRESSES + chunks * 8; }

std::string overBy(const std::string& what, std::uint64_t bytes, const std::string& limit, std::uint64_t limitBytes) {
    return what + " needs " + std::to_string(bytes) + " bytes, more than the device's " + limit + " of " +
           std::to_string(limitBytes) + " bytes (over by " + std::to_string(bytes - limitBytes) + ")";
}

}  // namespace

std::uint64_t stackSlotsFor(std::uint64_t workItems, std::uint32_t maxDepth, const DeviceInfo& device, bool slices) {
    if (!slices) return 1;
    return std::max<std::uint64_t>(1, std::min(workItems, device.maxStorageBufferRange / stackBytes(maxDepth)));
}

BufferLimits bufferLimits(const DeviceInfo& device, const GpuTuning& tuning) {
    BufferLimits limits;
    limits.addresses = device.bufferDeviceAddress;
    limits.bindings = device.maxPerStageStorageBuffers;
    // The kernel's chunk size is a 32-bit specialization constant.
    const std::uint64_t largest = device.maxMemoryAllocationSize ? device.maxMemoryAllocationSize : device.maxStorageBufferRange;
    const std::uint64_t allocation = std::min<std::uint64_t>(largest, 0xFFFFFFFFu);
    limits.bindingBytes = limits.deviceBindingBytes = device.maxStorageBufferRange;
    limits.chunkBytes = allocation / DACRT_CHUNK_ALIGNMENT * DACRT_CHUNK_ALIGNMENT;
    limits.memoryBytes = device.deviceLocalBytes;
    limits.bindingLimit = "maxStorageBufferRange";
    limits.chunkLimit = "maxMemoryAllocationSize";
    limits.memoryLimit = "device-local memory";
    if (tuning.bufferBytes && tuning.bufferBytes < limits.bindingBytes) {
        limits.bindingBytes = tuning.bufferBytes;
        limits.bindingLimit = "buffer cap (GpuTuning::bufferBytes)";
    }
    const std::uint64_t chunkCap = std::max<std::uint64_t>(tuning.chunkBytes / DACRT_CHUNK_ALIGNMENT, 1) * DACRT_CHUNK_ALIGNMENT;
    if (tuning.chunkBytes && chunkCap < limits.chunkBytes) {
        limits.chunkBytes = chunkCap;
        limits.chunkLimit = "chunk cap (GpuTuning::chunkBytes)";
    }
    if (tuning.memoryBytes && (!limits.memoryBytes || tuning.memoryBytes < limits.memoryBytes)) {
        limits.memoryBytes = tuning.memoryBytes;
        limits.memoryLimit = "memory cap (GpuTuning::memoryBytes)";
    }
    return limits;
}

DacrtBufferPlan planDacrtBuffers(const DacrtBufferCounts& c) {
    DacrtBufferPlan p{};
    p[DACRT_BINDING_RAYS] = {"rays", c.rays * sizeof(Ray)};
    p[DACRT_BINDING_TRIANGLES] = {"triangles", c.triangles * sizeof(Triangle)};
    p[DACRT_BINDING_TRIANGLE_BOUNDS] = {"triangle bounds", c.triangles * sizeof(Bounds)};
    p[DACRT_BINDING_HITS] = {"hits", c.rays * sizeof(Hit)};
    p[DACRT_BINDING_RAY_IDS] = c.packets ? PlannedBuffer{"ray ids, scratch and packet sections",
                                                         packetSections(c.rayIds, c.rays, c.packets).end * 4}
                                         : PlannedBuffer{"ray ids and scratch", c.rayIds * 8};
    p[DACRT_BINDING_TRI_IDS] = {"triangle ids and scratch", c.triangleIds * 8};
    p[DACRT_BINDING_REGIONS] = {"regions", c.regions * sizeof(Region)};
    p[DACRT_BINDING_WORK_ITEMS] = {"work items", c.workItems * sizeof(WorkItem)};
    p[DACRT_BINDING_COUNTERS] = {"counters", sizeof(GpuCounters)};
    p[DACRT_BINDING_STATES] = {"traversal states", c.workItems * sizeof(TraversalState)};
    p[DACRT_BINDING_STACKS] = {"traversal stacks", (c.stackSlots ? c.stackSlots : c.workItems) * stackBytes(c.maxDepth)};
    p[DACRT_BINDING_SOURCE_RAYS] = {"primary rays (secondary passes)", std::max<std::uint64_t>(c.sourceRays, 1) * sizeof(Ray)};
    p[DACRT_BINDING_SOURCE_HITS] = {"primary hits (secondary passes)", std::max<std::uint64_t>(c.sourceRays, 1) * sizeof(Hit)};
    p[DACRT_BINDING_ADDRESSES] = {"chunk table (addressed arrays)", chunkTableBytes(DACRT_ADDRESSED_ARRAYS)};
    p[DACRT_BINDING_PACKETS] = {"ray packets", std::max<std::uint64_t>(c.packets, 1) * sizeof(PacketBounds)};
    return p;
}

void chunkAddressedArrays(DacrtBufferPlan& plan, std::uint64_t chunkBytes) {
    std::uint64_t chunks = 0;
    for (std::uint32_t binding : kAddressedBindings) {
        plan[binding].chunkBytes = chunkBytes;
        chunks += chunksOf(plan[binding]);
    }
    plan[DACRT_BINDING_ADDRESSES].bytes = chunkTableBytes(chunks);
}

bool addressLargeArrays(DacrtBufferPlan& plan, const BufferLimits& limits) {
    if (limits.bindings && DACRT_BINDING_COUNT > limits.bindings)
        throw InputError("the gpu kernel binds " + std::to_string(DACRT_BINDING_COUNT) + " storage buffers, more than " +
                         "the device's maxPerStageDescriptorStorageBuffers of " + std::to_string(limits.bindings));
    // Element indices are 32-bit in the kernels, and signed where they index memory.
    constexpr std::array<std::uint64_t, DACRT_ADDRESSED_ARRAYS> kElementBytes = {64, 48, 32, 16, 4, 4, 64, 16};
    for (std::size_t a = 0; a < kAddressedBindings.size(); ++a) {
        const PlannedBuffer& b = plan[kAddressedBindings[a]];
        if (b.bytes / kElementBytes[a] > (std::uint64_t(1) << 31))
            throw InputError(std::string("the device array of ") + b.name + " has " + std::to_string(b.bytes / kElementBytes[a]) +
                             " elements, more than the kernels' 32-bit indices reach (2^31); render fewer pixels or " +
                             "split the scene");
    }
    bool beyondBinding = false;
    for (std::uint32_t k = 0; k < plan.size(); ++k) {
        const PlannedBuffer& b = plan[k];
        const std::string what = std::string("the device buffer of ") + b.name;
        if (!isAddressed(k) && b.bytes > limits.deviceBindingBytes)
            throw InputError(overBy(what, b.bytes, "maxStorageBufferRange", limits.deviceBindingBytes) +
                             ", and the kernel reaches it through one binding; render fewer pixels or use fewer regions");
        if (!isAddressed(k) || b.bytes <= limits.bindingBytes) continue;
        if (!limits.addresses)
            throw InputError(overBy(what, b.bytes, limits.bindingLimit, limits.bindingBytes) +
                             ", and the device lacks bufferDeviceAddress to reach it in chunks; render fewer pixels " +
                             "or split the scene");
        beyondBinding = true;
    }
    if (beyondBinding) chunkAddressedArrays(plan, limits.chunkBytes);
    return beyondBinding;
}

void addToMemoryPlan(const DacrtBufferPlan& buffers, const BufferLimits& limits, MemoryPlan& plan,
                     const ResidentBuffers* reused, std::uint64_t alsoKept) {
    const bool addressed = chunkBytesOf(buffers) != 0;
    std::uint64_t total = alsoKept;
    for (std::size_t k = 0; k < buffers.size(); ++k) {
        const PlannedBuffer& b = buffers[k];
        total += b.bytes;
        if (reused && (*reused)[k]) continue;
        std::string name = std::string("device: ") + b.name;
        if (b.chunkBytes) name += " (" + std::to_string(chunksOf(b)) + (chunksOf(b) == 1 ? " chunk" : " chunks") + ")";
        plan.add(name, b.bytes);
    }
    if (addressed) {
        std::uint64_t chunks = 0;
        for (std::uint32_t binding : kAddressedBindings) chunks += chunksOf(buffers[binding]);
        plan.addWork("addressed chunks", chunks,
                     "arrays beyond one binding (" + limits.bindingLimit + ": " + std::to_string(limits.bindingBytes) +
                     " bytes) reached by device address, in chunks of at most " + std::to_string(chunkBytesOf(buffers)) +
                     " bytes (" + limits.chunkLimit + ")");
    }
    if (limits.memoryBytes && total > limits.memoryBytes)
        throw DeviceLimitExceeded(overBy("the frame's device memory", total, limits.memoryLimit, limits.memoryBytes) +
                                      "; render fewer pixels",
                                  "device memory (" + limits.memoryLimit + ", bytes)", total, limits.memoryBytes);
}

DacrtBindingSet::DacrtBindingSet(const Context& context, const DacrtBufferPlan& plan, const ResidentBuffers& resident,
                                 BufferArena* arena) {
    for (std::size_t k = 0; k < plan.size(); ++k) {
        if (resident[k]) {
            if (resident[k]->size() < plan[k].bytes)
                throw InternalError(std::string("the resident buffer of ") + plan[k].name + " is smaller than planned");
            bound_[k] = resident[k];
            continue;
        }
        held_.push_back(arena ? arena->lease(context, std::uint32_t(k), plan[k])
                              : std::make_shared<Buffer>(context, plan[k].bytes, plan[k].name, BufferUse::Storage,
                                                         plan[k].chunkBytes));
        bound_[k] = held_.back().get();
    }
    if (chunkBytesOf(plan)) writeChunkTable(chunkBytesOf(plan));
}

// The addressed arrays' chunk addresses, as shaders/dacrt_bindings.glsl reads them. A buffer
// made elsewhere (resident, a primary pass's) is addressed as it is: in the same chunks, or in
// one chunk no longer than them.
void DacrtBindingSet::writeChunkTable(std::uint64_t chunkBytes) {
    std::vector<std::uint32_t> first;
    std::vector<VkDeviceAddress> addresses;
    addressed_ = true;
    for (std::uint32_t binding : kAddressedBindings)
        if (bound_[binding]->chunkCount() > 1) kernelChunkBytes_ = std::uint32_t(chunkBytes);
    for (std::uint32_t binding : kAddressedBindings) {
        const Buffer& b = *bound_[binding];
        if (!b.suitsChunks(chunkBytes))
            throw InternalError("the buffer of " + b.name() + " is not in the frame's chunks of " + std::to_string(chunkBytes) +
                                " bytes");
        first.push_back(std::uint32_t(addresses.size()));
        for (std::size_t c = 0; c < b.chunkCount(); ++c) addresses.push_back(b.deviceAddress(c));
    }
    Buffer& table = *bound_[DACRT_BINDING_ADDRESSES];
    table.upload(first.data(), first.size() * sizeof(first[0]));
    table.upload(addresses.data(), addresses.size() * sizeof(addresses[0]), DACRT_CHUNK_TABLE_ADDRESSES);
}

void DacrtBindingSet::bindTo(ComputePipeline& pipeline) const {
    pipeline.bind(std::vector<const Buffer*>(bound_.begin(), bound_.end()));
}

}  // namespace dacrt::gpu
