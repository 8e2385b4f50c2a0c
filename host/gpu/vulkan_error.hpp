#pragma once
// Every Vulkan call that returns a VkResult goes through VK_CHECK: a failure throws with the
// call, the result's name, the file and the line.
#include <stdexcept>
#include <string>

#include <vulkan/vulkan.h>

#include "gpu/vulkan_names.hpp"

namespace dacrt::gpu {

class VulkanError : public std::runtime_error {
public:
    VulkanError(const std::string& call, VkResult result, const char* file, int line)
        : std::runtime_error(call + " failed with " + resultName(result) + " at " + file + ":" + std::to_string(line)),
          result_(result) {}
    VkResult result() const { return result_; }

private:
    VkResult result_;
};

}  // namespace dacrt::gpu

#define VK_CHECK(call)                                                                       \
    do {                                                                                     \
        const VkResult vkCheckResult_ = (call);                                              \
        if (vkCheckResult_ != VK_SUCCESS)                                                    \
            throw ::dacrt::gpu::VulkanError(#call, vkCheckResult_, __FILE__, __LINE__);      \
    } while (0)
