#include "gpu/compute_pipeline.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/errors.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {

ComputePipeline::ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                                 std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization,
                                 std::string name)
    : ComputePipeline(context, spirv, std::vector<VkDescriptorType>(bindingCount, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                      pushConstantBytes, specialization, std::move(name)) {}

ComputePipeline::ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv,
                                 std::vector<VkDescriptorType> bindingTypes, std::uint32_t pushConstantBytes,
                                 const std::vector<std::uint32_t>& specialization, std::string name)
    : device_(context.device()), types_(std::move(bindingTypes)), pushBytes_(pushConstantBytes), name_(std::move(name)) {
    const std::uint32_t bindingCount = std::uint32_t(types_.size());
    try {
        VkShaderModuleCreateInfo moduleInfo{};
        moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        moduleInfo.codeSize = spirv.size_bytes();
        moduleInfo.pCode = spirv.data();
        VK_CHECK(vkCreateShaderModule(device_, &moduleInfo, nullptr, &module_));

        std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
        for (std::uint32_t b = 0; b < bindingCount; ++b)
            bindings[b] = VkDescriptorSetLayoutBinding{b, types_[b], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
        VkDescriptorSetLayoutCreateInfo setInfo{};
        setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
        setInfo.bindingCount = bindingCount;
        setInfo.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_));

        VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
        VkPipelineLayoutCreateInfo layoutInfo{};
        layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout_;
        layoutInfo.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
        layoutInfo.pPushConstantRanges = &push;
        VK_CHECK(vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &layout_));

        std::vector<VkSpecializationMapEntry> entries(specialization.size());
        for (std::uint32_t i = 0; i < entries.size(); ++i) entries[i] = VkSpecializationMapEntry{i, i * 4, 4};
        VkSpecializationInfo spec{std::uint32_t(entries.size()), entries.data(), specialization.size() * 4, specialization.data()};
        VkComputePipelineCreateInfo pipelineInfo{};
        pipelineInfo.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        pipelineInfo.stage = VkPipelineShaderStageCreateInfo{};
        pipelineInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipelineInfo.stage.module = module_;
        pipelineInfo.stage.pName = "main";
        if (context.info().fullSubgroups) pipelineInfo.stage.flags = VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT_EXT;
        pipelineInfo.stage.pSpecializationInfo = specialization.empty() ? nullptr : &spec;
        pipelineInfo.layout = layout_;
        VK_CHECK(vkCreateComputePipelines(device_, context.pipelineCache(), 1, &pipelineInfo, nullptr, &pipeline_));

        std::vector<VkDescriptorPoolSize> sizes;
        for (VkDescriptorType t : types_) {
            auto it = std::find_if(sizes.begin(), sizes.end(), [&](const VkDescriptorPoolSize& p) { return p.type == t; });
            if (it == sizes.end()) sizes.push_back({t, 1});
            else ++it->descriptorCount;
        }
        VkDescriptorPoolCreateInfo poolInfo{};
        poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
        poolInfo.maxSets = 1;
        poolInfo.poolSizeCount = std::uint32_t(sizes.size());
        poolInfo.pPoolSizes = sizes.data();
        VK_CHECK(vkCreateDescriptorPool(device_, &poolInfo, nullptr, &pool_));
        VkDescriptorSetAllocateInfo allocInfo{};
        allocInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
        allocInfo.descriptorPool = pool_;
        allocInfo.descriptorSetCount = 1;
        allocInfo.pSetLayouts = &setLayout_;
        VK_CHECK(vkAllocateDescriptorSets(device_, &allocInfo, &set_));
    } catch (...) {
        destroy();
        throw;
    }
}

ComputePipeline::~ComputePipeline() { destroy(); }

void ComputePipeline::destroy() {
    if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
    if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
    if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
    if (setLayout_) vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
    if (module_) vkDestroyShaderModule(device_, module_, nullptr);
    pool_ = VK_NULL_HANDLE;
    pipeline_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    setLayout_ = VK_NULL_HANDLE;
    module_ = VK_NULL_HANDLE;
}

void ComputePipeline::bind(const std::vector<const Buffer*>& buffers) {
    if (buffers.size() != types_.size())
        throw std::logic_error("pipeline '" + name_ + "' has " + std::to_string(types_.size()) + " bindings, got " +
                               std::to_string(buffers.size()) + " buffers");
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes;
    for (std::uint32_t b = 0; b < buffers.size(); ++b) {
        if (types_[b] != VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) continue;  // written by its owner (an acceleration structure)
        if (!buffers[b])
            throw std::logic_error("pipeline '" + name_ + "': storage buffer binding " + std::to_string(b) + " given no buffer");
        infos[b] = VkDescriptorBufferInfo{buffers[b]->handle(), 0, buffers[b]->bindingRange()};
        VkWriteDescriptorSet w{};
        w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w.dstSet = set_;
        w.dstBinding = b;
        w.descriptorCount = 1;
        w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w.pBufferInfo = &infos[b];
        writes.push_back(w);
    }
    vkUpdateDescriptorSets(device_, std::uint32_t(writes.size()), writes.data(), 0, nullptr);
}

void ComputePipeline::bindAccelerationStructure(std::uint32_t binding, VkAccelerationStructureKHR structure) {
    VkWriteDescriptorSetAccelerationStructureKHR as{};
    as.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
    as.accelerationStructureCount = 1;
    as.pAccelerationStructures = &structure;
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.pNext = &as;
    w.dstSet = set_;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

}  // namespace dacrt::gpu
