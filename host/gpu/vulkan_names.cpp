#include "gpu/vulkan_names.hpp"

#include <cctype>

#include <vulkan/vulkan.hpp>  // with vulkan_to_string.hpp

namespace dacrt::gpu {

std::string resultName(VkResult result) {
    // vulkan.hpp names results in CamelCase ("ErrorDeviceLost"); the C name is the same words
    // upper-cased and joined by underscores, behind "VK_".
    const std::string camel = ::vk::to_string(::vk::Result(result));
    if (camel.rfind("invalid", 0) == 0) return "VkResult " + std::to_string(int(result)) + " (unknown)";
    std::string name = "VK_";
    for (std::size_t i = 0; i < camel.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(camel[i]);
        if (i > 0 && std::isupper(c) && std::islower(static_cast<unsigned char>(camel[i - 1]))) name += '_';
        name += char(std::toupper(c));
    }
    return name;
}

std::string deviceTypeName(VkPhysicalDeviceType type) { return ::vk::to_string(::vk::PhysicalDeviceType(type)); }

}  // namespace dacrt::gpu
