#pragma once
// The one dispatch helper of the small Vulkan layer: timestamped, in the manner of pbrt-v4's
// GPUParallelFor.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/context.hpp"
#include "gpu/compute_pipeline.hpp"

namespace dacrt::gpu {

// Records named dispatches into one command buffer, each bracketed by GPU timestamps and
// separated from the previous one by a compute-to-compute memory barrier; submits once.
class DispatchRecorder {
public:
    DispatchRecorder(const Context& context, std::uint32_t maxDispatches);
    ~DispatchRecorder();
    DispatchRecorder(const DispatchRecorder&) = delete;
    DispatchRecorder& operator=(const DispatchRecorder&) = delete;

    void dispatch(const std::string& name, const ComputePipeline& pipeline, std::uint32_t groups, const void* push);
    void submitAndWait();
    std::uint32_t dispatchCount() const { return std::uint32_t(names_.size()); }
    // Per dispatch, in recording order: name and GPU time in ms (0 if the device has no
    // timestamps). Valid after submitAndWait.
    std::vector<std::pair<std::string, double>> timingsMs() const;

private:
    const Context& context_;
    VkCommandBuffer commands_ = VK_NULL_HANDLE;
    VkQueryPool queries_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    std::uint32_t maxDispatches_;
    std::vector<std::string> names_;
    std::vector<std::uint64_t> stamps_;
};

}  // namespace dacrt::gpu
