#pragma once
// The one dispatch helper of the small Vulkan layer: timestamped, in the manner of pbrt-v4's
// GPUParallelFor.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/context.hpp"
#include <functional>

#include "gpu/compute_pipeline.hpp"

namespace dacrt::gpu {

// Records named steps (dispatches, acceleration-structure builds) into one command buffer,
// each bracketed by GPU timestamps and separated from the previous one by a memory barrier
// from the stage that wrote to the stage that reads; submits once.
class DispatchRecorder {
public:
    DispatchRecorder(const Context& context, std::uint32_t maxDispatches);
    ~DispatchRecorder();
    DispatchRecorder(const DispatchRecorder&) = delete;
    DispatchRecorder& operator=(const DispatchRecorder&) = delete;

    void dispatch(const std::string& name, const ComputePipeline& pipeline, std::uint32_t groups, const void* push);
    // Acceleration-structure commands, recorded by `commands` into the command buffer.
    void buildAccelerationStructures(const std::string& name, const std::function<void(VkCommandBuffer)>& commands);
    void submitAndWait();
    std::uint32_t dispatchCount() const { return std::uint32_t(names_.size()); }
    // Per dispatch, in recording order: name and GPU time in ms (0 if the device has no
    // timestamps). Valid after submitAndWait.
    std::vector<std::pair<std::string, double>> timingsMs() const;

private:
    // The barrier before step `index` and its first timestamp; the stage it runs in.
    void beginStep(const std::string& name, VkPipelineStageFlags stage, VkAccessFlags reads);
    void endStep(VkPipelineStageFlags stage, VkAccessFlags writes);

    const Context& context_;
    VkPipelineStageFlags lastStage_ = 0;
    VkAccessFlags lastWrites_ = 0;
    VkCommandBuffer commands_ = VK_NULL_HANDLE;
    VkQueryPool queries_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    std::uint32_t maxDispatches_;
    std::vector<std::string> names_;
    std::vector<std::uint64_t> stamps_;
};

}  // namespace dacrt::gpu
