#pragma once
// The DACRT kernels' one binding set (DACRT_BINDING_* in shaders/layout.h): every storage
// buffer sized from the frame's counts, planned before anything is allocated, then created
// and bound. The tracer, the building-block tests and the block benchmark all use it.
#include <array>
#include <cstdint>
#include <vector>

#include "core/shader_layout.hpp"
#include "cpu/memory_plan.hpp"
#include "gpu/buffer.hpp"
#include "gpu/compute_pipeline.hpp"

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
};

// The traversal stacks a frame keeps: none is saved without a loop budget (one slot, bound and
// never used); with one, a stack per work item as far as the device's largest buffer holds them.
std::uint64_t stackSlotsFor(std::uint64_t workItems, std::uint32_t maxDepth, const DeviceInfo& device, bool slices);

struct PlannedBuffer {
    const char* name;    // for the memory plan and error messages
    std::uint64_t bytes;
};

// Index k is binding k.
using DacrtBufferPlan = std::array<PlannedBuffer, DACRT_BINDING_COUNT>;

DacrtBufferPlan planDacrtBuffers(const DacrtBufferCounts& counts);

// Appends "device: NAME" entries to plan, and throws InputError naming the first buffer that
// exceeds the device's maxStorageBufferRange, with the limit and the excess. Bindings that
// `reused` names (buffers that exist already) are checked but not added.
using ResidentBuffers = std::array<Buffer*, DACRT_BINDING_COUNT>;
void addToMemoryPlan(const DacrtBufferPlan& buffers, const DeviceInfo& device, MemoryPlan& plan,
                     const ResidentBuffers* reused = nullptr);

// Buffers that outlive a binding set, for the bindings that name one (null: the set makes it):
// ResidentBuffers, above.

class DacrtBindingSet {
public:
    DacrtBindingSet(const Context& context, const DacrtBufferPlan& plan, const ResidentBuffers& resident = {});

    Buffer& operator[](std::uint32_t binding) { return *bound_[binding]; }
    const Buffer& operator[](std::uint32_t binding) const { return *bound_[binding]; }
    // Points every binding of the pipeline's set at its buffer.
    void bindTo(ComputePipeline& pipeline) const;

private:
    std::vector<Buffer> owned_;   // the bindings without a resident buffer
    ResidentBuffers bound_{};     // index = binding; into owned_ (its storage moves with it) or resident
};

}  // namespace dacrt::gpu
