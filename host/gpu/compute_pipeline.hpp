#pragma once
// A compute pipeline with its descriptor set, of the small Vulkan layer.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "gpu/context.hpp"
#include "gpu/buffer.hpp"

namespace dacrt::gpu {

// A compute pipeline over `bindingCount` storage buffers (bindings 0..n-1 of set 0), with
// push constants and uint32 specialization constants (constant_id 0..m-1).
class ComputePipeline {
public:
    ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                    std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization, std::string name);
    // Bindings 0..n-1 of the given types (storage buffers, an acceleration structure).
    ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv, std::vector<VkDescriptorType> bindingTypes,
                    std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization, std::string name);
    ~ComputePipeline();
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;

    // Points binding k at buffers[k] (null for a binding that is not a storage buffer).
    void bind(const std::vector<const Buffer*>& buffers);
    void bindAccelerationStructure(std::uint32_t binding, VkAccelerationStructureKHR structure);
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
    std::vector<VkDescriptorType> types_;
    std::uint32_t pushBytes_ = 0;
    std::string name_;
};

}  // namespace dacrt::gpu
