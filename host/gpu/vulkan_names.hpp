#pragma once
// Names of Vulkan enums as the specification spells them, from the tables libvulkan-dev ships
// in vulkan_to_string.hpp.
#include <string>

#include <vulkan/vulkan.h>

namespace dacrt::gpu {

std::string resultName(VkResult result);                  // VK_ERROR_DEVICE_LOST
std::string deviceTypeName(VkPhysicalDeviceType type);    // DiscreteGpu, Cpu, ...

}  // namespace dacrt::gpu
