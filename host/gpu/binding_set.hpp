#pragma once
// The DACRT kernels' one binding set (DACRT_BINDING_* in shaders/layout.h): every storage
// buffer sized from the frame's counts, planned before anything is allocated, then created
// and bound. The tracer, the building-block tests and the block benchmark all use it.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <dacrt/backend_tuning.hpp>

#include "core/shader_layout.hpp"
#include "cpu/memory_plan.hpp"
#include "gpu/buffer.hpp"
#include "gpu/compute_pipeline.hpp"
#include "gpu/device_limit_exceeded.hpp"

namespace dacrt::gpu {

// Element counts behind every binding.
struct DacrtBufferCounts {
    std::uint64_t rays = 0;
    std::uint64_t triangles = 0;
    std::uint64_t rayIds = 0;        // the ray id array (its scratch half is as long again)
    std::uint64_t triangleIds = 0;   // the triangle id array, every ray group's copy (likewise)
    std::uint64_t regions = 0;       // region slots
    std::uint64_t workItems = 0;
    std::uint32_t maxDepth = 0;      // traversal stack depth per work item
    // Traversal stacks kept between slices, taken in turn by the work items that save one
    // (stackSlotsFor); 0: one per work item.
    std::uint64_t stackSlots = 0;
    std::uint64_t sourceRays = 0;    // secondary passes: the primary rays they start from (0: a primary pass)
    std::uint64_t packets = 0;       // ray packets (gpu/ray_packets.hpp); the ray ids then have their sections
};

// The traversal stacks a frame keeps: none is saved without a loop budget (one slot, bound and
// never used); with one, a stack per work item as far as the device's largest buffer holds them.
std::uint64_t stackSlotsFor(std::uint64_t workItems, std::uint32_t maxDepth, const DeviceInfo& device, bool slices);

struct PlannedBuffer {
    const char* name;    // for the memory plan and error messages
    std::uint64_t bytes;
    // 0: one allocation, bound whole; else reached by device address in chunks of this many
    // bytes (the addressed kernels, DACRT_ADDRESSED in shaders/dacrt_bindings.glsl).
    std::uint64_t chunkBytes = 0;
};

// Index k is binding k.
using DacrtBufferPlan = std::array<PlannedBuffer, DACRT_BINDING_COUNT>;

// The bindings of the arrays the addressed kernels reach by address, by DACRT_ARRAY_* index.
constexpr std::array<std::uint32_t, DACRT_ADDRESSED_ARRAYS> kAddressedBindings = {
    DACRT_BINDING_RAYS,    DACRT_BINDING_TRIANGLES, DACRT_BINDING_TRIANGLE_BOUNDS, DACRT_BINDING_HITS,
    DACRT_BINDING_RAY_IDS, DACRT_BINDING_TRI_IDS,   DACRT_BINDING_SOURCE_RAYS,     DACRT_BINDING_SOURCE_HITS};

// What bounds one buffer of a frame: the device's limits, or the lower caps GpuTuning sets
// (bufferBytes, memoryBytes: tests split small scenes with them). Each names its limit.
struct BufferLimits {
    std::uint64_t bindingBytes = 0;  // one binding's reach: maxStorageBufferRange
    std::uint64_t deviceBindingBytes = 0;  // the same, never capped: for the arrays always bound
    std::uint64_t chunkBytes = 0;    // one addressed chunk: maxMemoryAllocationSize, a multiple of DACRT_CHUNK_ALIGNMENT
    std::uint64_t memoryBytes = 0;   // every buffer of a frame together: the largest device-local heap
    bool addresses = false;          // the device has bufferDeviceAddress
    std::uint32_t bindings = 0;      // maxPerStageDescriptorStorageBuffers
    std::string bindingLimit, chunkLimit, memoryLimit;  // "maxStorageBufferRange", ...
};
BufferLimits bufferLimits(const DeviceInfo& device, const GpuTuning& tuning);

// Planned with the same counts, every array in one binding: whether the addressed kernels
// must run (some addressed array exceeds limits.bindingBytes). If so, the addressed arrays
// are planned in chunks of limits.chunkBytes. Throws InputError, naming the limit and the
// excess, for a buffer no plan can hold: an array beyond one binding on a device without
// buffer device addresses, or one that the addressed kernels do not address (regions, work
// items, traversal states and stacks).
bool addressLargeArrays(DacrtBufferPlan& plan, const BufferLimits& limits);
// Plans the addressed arrays in chunks of chunkBytes, and the chunk table that names them.
void chunkAddressedArrays(DacrtBufferPlan& plan, std::uint64_t chunkBytes);
inline std::uint64_t chunkBytesOf(const DacrtBufferPlan& plan) { return plan[DACRT_BINDING_RAYS].chunkBytes; }

DacrtBufferPlan planDacrtBuffers(const DacrtBufferCounts& counts);

// Appends "device: NAME" entries to plan (with their chunks, where addressed, and the limit
// that made them so), and throws InputError when the frame's buffers together exceed the
// device's memory (limits.memoryBytes), with the limit and the excess. Bindings that `reused`
// names (buffers that exist already) are counted in that sum but not added to the plan;
// `alsoKept` bytes (buffers the frame keeps from elsewhere) likewise.
using ResidentBuffers = std::array<Buffer*, DACRT_BINDING_COUNT>;
void addToMemoryPlan(const DacrtBufferPlan& buffers, const BufferLimits& limits, MemoryPlan& plan,
                     const ResidentBuffers* reused = nullptr, std::uint64_t alsoKept = 0);

// Buffers that outlive a binding set, for the bindings that name one (null: the set makes it):
// ResidentBuffers, above.

class BufferArena;

class DacrtBindingSet {
public:
    // Bindings without a resident buffer get one leased from `arena` (kept there for later
    // frames once this set is gone), else one of their own.
    DacrtBindingSet(const Context& context, const DacrtBufferPlan& plan, const ResidentBuffers& resident = {},
                    BufferArena* arena = nullptr);

    Buffer& operator[](std::uint32_t binding) { return *bound_[binding]; }
    const Buffer& operator[](std::uint32_t binding) const { return *bound_[binding]; }
    // Points every binding of the pipeline's set at its buffer.
    void bindTo(ComputePipeline& pipeline) const;
    // Whether the addressed kernels run on it, and their chunk size (DACRT_SPEC_CHUNK_BYTES):
    // 0 where every addressed array is one chunk.
    bool addressed() const { return addressed_; }
    std::uint32_t kernelChunkBytes() const { return kernelChunkBytes_; }

private:
    void writeChunkTable(std::uint64_t chunkBytes);

    std::vector<std::shared_ptr<Buffer>> held_;  // the bindings without a resident buffer: leased or own
    ResidentBuffers bound_{};     // index = binding; into held_ or resident
    bool addressed_ = false;
    std::uint32_t kernelChunkBytes_ = 0;
};

}  // namespace dacrt::gpu
