#include "vk_resources.hpp"

#include <cstring>

#include "errors.hpp"
#include "vk_check.hpp"

namespace dacrt::vk {

Buffer::Buffer(const Context& context, std::uint64_t bytes, std::string name)
    : device_(context.device()), bytes_(std::max<std::uint64_t>(bytes, 16)), name_(std::move(name)) {
    const DeviceInfo& info = context.info();
    if (bytes_ > info.maxStorageBufferRange)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(bytes_) + " bytes but the device's " +
                         "maxStorageBufferRange is " + std::to_string(info.maxStorageBufferRange) + " (over by " +
                         std::to_string(bytes_ - info.maxStorageBufferRange) + " bytes)");
    if (info.maxMemoryAllocationSize && bytes_ > info.maxMemoryAllocationSize)
        throw InputError("buffer '" + name_ + "' needs " + std::to_string(bytes_) + " bytes but the device's " +
                         "maxMemoryAllocationSize is " + std::to_string(info.maxMemoryAllocationSize));
    VkBufferCreateInfo bufferInfo{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bufferInfo.size = bytes_;
    bufferInfo.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bufferInfo.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VK_CHECK(vkCreateBuffer(device_, &bufferInfo, nullptr, &buffer_));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    const VkMemoryPropertyFlags hostVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    std::uint32_t type = context.memoryType(req.memoryTypeBits, hostVisible | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == UINT32_MAX) type = context.memoryType(req.memoryTypeBits, hostVisible);
    if (type == UINT32_MAX) {
        vkDestroyBuffer(device_, buffer_, nullptr);
        throw InputError("device '" + info.name + "' has no host-visible coherent memory for buffer '" + name_ + "'");
    }
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    const VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
    if (r != VK_SUCCESS) {
        vkDestroyBuffer(device_, buffer_, nullptr);
        if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
            throw InputError("buffer '" + name_ + "' (" + std::to_string(bytes_) + " bytes) does not fit in device memory (" +
                             resultName(r) + ")");
        VK_CHECK(r);
    }
    try {
        VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
        VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    } catch (...) {
        vkFreeMemory(device_, memory_, nullptr);
        vkDestroyBuffer(device_, buffer_, nullptr);
        throw;
    }
}

Buffer::Buffer(Buffer&& o) noexcept
    : device_(o.device_), buffer_(o.buffer_), memory_(o.memory_), mapped_(o.mapped_), bytes_(o.bytes_), name_(std::move(o.name_)) {
    o.buffer_ = VK_NULL_HANDLE;
    o.memory_ = VK_NULL_HANDLE;
    o.mapped_ = nullptr;
}

Buffer::~Buffer() {
    if (memory_) {
        if (mapped_) vkUnmapMemory(device_, memory_);
        vkFreeMemory(device_, memory_, nullptr);
    }
    if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
}

void Buffer::upload(const void* data, std::uint64_t bytes, std::uint64_t offset) {
    if (offset + bytes > bytes_) throw std::out_of_range("upload past the end of buffer '" + name_ + "'");
    if (bytes) std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
}

void Buffer::download(void* data, std::uint64_t bytes, std::uint64_t offset) const {
    if (offset + bytes > bytes_) throw std::out_of_range("download past the end of buffer '" + name_ + "'");
    if (bytes) std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
}

ComputePipeline::ComputePipeline(const Context& context, std::span<const std::uint32_t> spirv, std::uint32_t bindingCount,
                                 std::uint32_t pushConstantBytes, const std::vector<std::uint32_t>& specialization,
                                 std::string name)
    : device_(context.device()), bindings_(bindingCount), pushBytes_(pushConstantBytes), name_(std::move(name)) {
    try {
        VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        moduleInfo.codeSize = spirv.size_bytes();
        moduleInfo.pCode = spirv.data();
        VK_CHECK(vkCreateShaderModule(device_, &moduleInfo, nullptr, &module_));

        std::vector<VkDescriptorSetLayoutBinding> bindings(bindingCount);
        for (std::uint32_t b = 0; b < bindingCount; ++b)
            bindings[b] = VkDescriptorSetLayoutBinding{b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
        VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        setInfo.bindingCount = bindingCount;
        setInfo.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_));

        VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
        VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layoutInfo.setLayoutCount = 1;
        layoutInfo.pSetLayouts = &setLayout_;
        layoutInfo.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
        layoutInfo.pPushConstantRanges = &push;
        VK_CHECK(vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &layout_));

        std::vector<VkSpecializationMapEntry> entries(specialization.size());
        for (std::uint32_t i = 0; i < entries.size(); ++i) entries[i] = VkSpecializationMapEntry{i, i * 4, 4};
        VkSpecializationInfo spec{std::uint32_t(entries.size()), entries.data(), specialization.size() * 4, specialization.data()};
        VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        pipelineInfo.stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipelineInfo.stage.module = module_;
        pipelineInfo.stage.pName = "main";
        if (context.info().fullSubgroups) pipelineInfo.stage.flags = VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT_EXT;
        pipelineInfo.stage.pSpecializationInfo = specialization.empty() ? nullptr : &spec;
        pipelineInfo.layout = layout_;
        VK_CHECK(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline_));

        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, bindingCount};
        VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        poolInfo.maxSets = 1;
        poolInfo.poolSizeCount = 1;
        poolInfo.pPoolSizes = &size;
        VK_CHECK(vkCreateDescriptorPool(device_, &poolInfo, nullptr, &pool_));
        VkDescriptorSetAllocateInfo allocInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
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
    if (buffers.size() != bindings_)
        throw std::logic_error("pipeline '" + name_ + "' has " + std::to_string(bindings_) + " bindings, got " +
                               std::to_string(buffers.size()) + " buffers");
    std::vector<VkDescriptorBufferInfo> infos(buffers.size());
    std::vector<VkWriteDescriptorSet> writes(buffers.size());
    for (std::uint32_t b = 0; b < buffers.size(); ++b) {
        infos[b] = VkDescriptorBufferInfo{buffers[b]->handle(), 0, VK_WHOLE_SIZE};
        writes[b] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[b].dstSet = set_;
        writes[b].dstBinding = b;
        writes[b].descriptorCount = 1;
        writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[b].pBufferInfo = &infos[b];
    }
    vkUpdateDescriptorSets(device_, std::uint32_t(writes.size()), writes.data(), 0, nullptr);
}

DispatchRecorder::DispatchRecorder(const Context& context, std::uint32_t maxDispatches)
    : context_(context), maxDispatches_(maxDispatches) {
    VkDevice device = context.device();
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = context.commandPool();
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(device, &alloc, &commands_));
    if (context.info().timestamps) {
        VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = 2 * std::max(maxDispatches, 1u);
        VK_CHECK(vkCreateQueryPool(device, &q, nullptr, &queries_));
    }
    VkFenceCreateInfo f{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(device, &f, nullptr, &fence_));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(commands_, &begin));
    if (queries_) vkCmdResetQueryPool(commands_, queries_, 0, 2 * std::max(maxDispatches, 1u));
}

DispatchRecorder::~DispatchRecorder() {
    VkDevice device = context_.device();
    if (fence_) vkDestroyFence(device, fence_, nullptr);
    if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
    if (commands_) vkFreeCommandBuffers(device, context_.commandPool(), 1, &commands_);
}

void DispatchRecorder::dispatch(const std::string& name, const ComputePipeline& pipeline, std::uint32_t groups,
                                const void* push) {
    const std::uint32_t index = std::uint32_t(names_.size());
    if (index >= maxDispatches_) throw std::logic_error("more dispatches than planned (" + std::to_string(maxDispatches_) + ")");
    if (index > 0) {
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
        vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                             &barrier, 0, nullptr, 0, nullptr);
    }
    names_.push_back(name);
    if (queries_) vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 2 * index);
    vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline());
    VkDescriptorSet set = pipeline.descriptorSet();
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &set, 0, nullptr);
    if (pipeline.pushConstantBytes())
        vkCmdPushConstants(commands_, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, pipeline.pushConstantBytes(), push);
    if (groups > 0) vkCmdDispatch(commands_, groups, 1, 1);
    if (queries_) vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 2 * index + 1);
}

void DispatchRecorder::submitAndWait() {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
    VK_CHECK(vkEndCommandBuffer(commands_));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands_;
    VK_CHECK(vkQueueSubmit(context_.queue(), 1, &submit, fence_));
    VK_CHECK(vkWaitForFences(context_.device(), 1, &fence_, VK_TRUE, UINT64_MAX));
    if (queries_ && !names_.empty()) {
        stamps_.resize(2 * names_.size());
        VK_CHECK(vkGetQueryPoolResults(context_.device(), queries_, 0, std::uint32_t(stamps_.size()),
                                       stamps_.size() * sizeof(std::uint64_t), stamps_.data(), sizeof(std::uint64_t),
                                       VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    }
}

std::vector<std::pair<std::string, double>> DispatchRecorder::timingsMs() const {
    std::vector<std::pair<std::string, double>> t;
    for (std::size_t i = 0; i < names_.size(); ++i) {
        const double ms = stamps_.size() > 2 * i + 1
                              ? double(stamps_[2 * i + 1] - stamps_[2 * i]) * context_.timestampPeriodNs() * 1e-6
                              : 0.0;
        t.emplace_back(names_[i], ms);
    }
    return t;
}

}  // namespace dacrt::vk
