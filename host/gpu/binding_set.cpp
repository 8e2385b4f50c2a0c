#include "gpu/binding_set.hpp"

#include <algorithm>
#include <string>

#include "core/errors.hpp"

namespace dacrt::gpu {

namespace {

std::uint64_t stackBytes(std::uint32_t maxDepth) { return (2 * std::uint64_t(maxDepth) + 1) * sizeof(StackEntry); }

}  // namespace

std::uint64_t stackSlotsFor(std::uint64_t workItems, std::uint32_t maxDepth, const DeviceInfo& device, bool slices) {
    if (!slices) return 1;
    return std::max<std::uint64_t>(1, std::min(workItems, device.maxStorageBufferRange / stackBytes(maxDepth)));
}

DacrtBufferPlan planDacrtBuffers(const DacrtBufferCounts& c) {
    DacrtBufferPlan p{};
    p[DACRT_BINDING_RAYS] = {"rays", c.rays * sizeof(Ray)};
    p[DACRT_BINDING_TRIANGLES] = {"triangles", c.triangles * sizeof(Triangle)};
    p[DACRT_BINDING_TRIANGLE_BOUNDS] = {"triangle bounds", c.triangles * sizeof(Bounds)};
    p[DACRT_BINDING_HITS] = {"hits", c.rays * sizeof(Hit)};
    p[DACRT_BINDING_RAY_IDS] = {"ray ids and scratch", c.rayIds * 8};
    p[DACRT_BINDING_TRI_IDS] = {"triangle ids and scratch", c.triangleIds * 8};
    p[DACRT_BINDING_REGIONS] = {"regions", c.regions * sizeof(Region)};
    p[DACRT_BINDING_WORK_ITEMS] = {"work items", c.workItems * sizeof(WorkItem)};
    p[DACRT_BINDING_COUNTERS] = {"counters", sizeof(GpuCounters)};
    p[DACRT_BINDING_STATES] = {"traversal states", c.workItems * sizeof(TraversalState)};
    p[DACRT_BINDING_STACKS] = {"traversal stacks", (c.stackSlots ? c.stackSlots : c.workItems) * stackBytes(c.maxDepth)};
    p[DACRT_BINDING_SOURCE_RAYS] = {"primary rays (secondary passes)", std::max<std::uint64_t>(c.sourceRays, 1) * sizeof(Ray)};
    p[DACRT_BINDING_SOURCE_HITS] = {"primary hits (secondary passes)", std::max<std::uint64_t>(c.sourceRays, 1) * sizeof(Hit)};
    return p;
}

void addToMemoryPlan(const DacrtBufferPlan& buffers, const DeviceInfo& device, MemoryPlan& plan,
                     const ResidentBuffers* reused) {
    for (std::size_t k = 0; k < buffers.size(); ++k) {
        const PlannedBuffer& b = buffers[k];
        if (!reused || !(*reused)[k]) plan.add(std::string("device: ") + b.name, b.bytes);
        if (b.bytes > device.maxStorageBufferRange)
            throw InputError(std::string("the device buffer of ") + b.name + " needs " + std::to_string(b.bytes) +
                             " bytes, more than the device's maxStorageBufferRange of " +
                             std::to_string(device.maxStorageBufferRange) + " bytes (over by " +
                             std::to_string(b.bytes - device.maxStorageBufferRange) +
                             "); render fewer pixels or split the scene");
    }
}

DacrtBindingSet::DacrtBindingSet(const Context& context, const DacrtBufferPlan& plan, const ResidentBuffers& resident) {
    owned_.reserve(plan.size());  // no reallocation: bound_ points into it
    for (std::size_t k = 0; k < plan.size(); ++k) {
        if (resident[k]) {
            if (resident[k]->size() < plan[k].bytes)
                throw InternalError(std::string("the resident buffer of ") + plan[k].name + " is smaller than planned");
            bound_[k] = resident[k];
            continue;
        }
        owned_.emplace_back(context, plan[k].bytes, plan[k].name);
        bound_[k] = &owned_.back();
    }
}

void DacrtBindingSet::bindTo(ComputePipeline& pipeline) const {
    pipeline.bind(std::vector<const Buffer*>(bound_.begin(), bound_.end()));
}

}  // namespace dacrt::gpu
