#include "gpu/dispatch_recorder.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/errors.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {

DispatchRecorder::DispatchRecorder(const Context& context, std::uint32_t maxDispatches)
    : context_(context), maxDispatches_(maxDispatches) {
    VkDevice device = context.device();
    VkCommandBufferAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    alloc.commandPool = context.commandPool();
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(device, &alloc, &commands_));
    if (context.info().timestamps) {
        VkQueryPoolCreateInfo q{};
        q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        q.queryType = VK_QUERY_TYPE_TIMESTAMP;
        q.queryCount = 2 * std::max(maxDispatches, 1u);
        VK_CHECK(vkCreateQueryPool(device, &q, nullptr, &queries_));
    }
    VkFenceCreateInfo f{};
    f.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VK_CHECK(vkCreateFence(device, &f, nullptr, &fence_));
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
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

void DispatchRecorder::beginStep(const std::string& name, VkPipelineStageFlags stage, VkAccessFlags reads) {
    const std::uint32_t index = std::uint32_t(names_.size());
    if (index >= maxDispatches_) throw std::logic_error("more dispatches than planned (" + std::to_string(maxDispatches_) + ")");
    if (index > 0) {
        VkMemoryBarrier barrier{};
        barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
        barrier.srcAccessMask = lastWrites_;
        barrier.dstAccessMask = reads;
        vkCmdPipelineBarrier(commands_, lastStage_, stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
    }
    names_.push_back(name);
    if (queries_) vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 2 * index);
}

void DispatchRecorder::endStep(VkPipelineStageFlags stage, VkAccessFlags writes) {
    const std::uint32_t index = std::uint32_t(names_.size()) - 1;
    if (queries_) vkCmdWriteTimestamp(commands_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 2 * index + 1);
    lastStage_ = stage;
    lastWrites_ = writes;
}

void DispatchRecorder::dispatch(const std::string& name, const ComputePipeline& pipeline, std::uint32_t groups,
                                const void* push) {
    constexpr VkAccessFlags kReads =
        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    // Only devices with acceleration structures know their access bit.
    beginStep(name, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
              context_.info().rayQuery ? kReads : VkAccessFlags(VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT));
    vkCmdBindPipeline(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline());
    VkDescriptorSet set = pipeline.descriptorSet();
    vkCmdBindDescriptorSets(commands_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &set, 0, nullptr);
    if (pipeline.pushConstantBytes())
        vkCmdPushConstants(commands_, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, pipeline.pushConstantBytes(), push);
    if (groups > 0) vkCmdDispatch(commands_, groups, 1, 1);
    endStep(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
}

void DispatchRecorder::buildAccelerationStructures(const std::string& name,
                                                   const std::function<void(VkCommandBuffer)>& commands) {
    beginStep(name, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
              VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR |
                  VK_ACCESS_SHADER_READ_BIT);
    commands(commands_);
    endStep(VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
}

void DispatchRecorder::submitAndWait() {
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
    VK_CHECK(vkEndCommandBuffer(commands_));
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
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

}  // namespace dacrt::gpu
