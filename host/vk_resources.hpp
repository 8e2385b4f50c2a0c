#pragma once
// RAII buffers, compute pipelines and the one dispatch helper (timestamped, in the manner of
// pbrt-v4's GPUParallelFor) of the small Vulkan layer.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "vk_context.hpp"

namespace dacrt::vk {

// A storage buffer in host-visible, coherent memory (device-local too where the device has
// such memory): uploads and readbacks are plain copies.
class Buffer {
public:
    Buffer(const Context& context, std::uint64_t bytes, std::string name);
    ~Buffer();
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&&) = delete;
    Buffer(const Buffer&) = delete;

    VkBuffer handle() const { return buffer_; }
    std::uint64_t size() const { return bytes_; }
    const std::string& name() const { return name_; }
    void upload(const void* data, std::uint64_t bytes, std::uint64_t offset = 0);
    void download(void* data, std::uint64_t bytes, std::uint64_t offset = 0) const;

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    void* mapped_ = nullptr;
    std::uint64_t bytes_ = 0;
    std::string name_;
};

// A compute pipeline over `bindingCount` storage buffers (bindings 0..n-1 of set 0), with
// push constants and uint32 specialization constants (constant_id 0..m-1).
class ComputePipeline {
public:
    ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                    std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization, std::string name);
    ~ComputePipeline();
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;

    // Points binding k at buffers[k].
    void bind(const std::vector<const Buffer*>& buffers);
    const std::string& name() const { return name_; }
    VkPipeline pipeline() const { return pipeline_; }
    VkPipelineLayout layout() const { return layout_; }
    VkDescriptorSet descriptorSet() const { return set_; }
    std::uint32_t pushConstantBytes() const { return pushBytes_; }

private:
    void destroy();  // releases the Vulkan handles; safe on a partly built pipeline
    VkDevice device_ = VK_NULL_HANDLE;
    VkShaderModule module_ = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
    std::uint32_t bindings_ = 0;
    std::uint32_t pushBytes_ = 0;
    std::string name_;
};

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

}  // namespace dacrt::vk
