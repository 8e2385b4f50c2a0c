#pragma once
// Instance, device choice and the logical device: the root of the small Vulkan layer.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include <dacrt/devices.hpp>

namespace dacrt::gpu {

// A device's properties and limits (the public <dacrt/devices.hpp> names them) with its type
// as Vulkan gives it.
struct DeviceInfo : VulkanDeviceProperties {
    VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    bool isCpu() const { return type == VK_PHYSICAL_DEVICE_TYPE_CPU; }  // lavapipe, SwiftShader
    std::string typeName() const;  // as vulkan.hpp names it: DiscreteGpu, Cpu, ...
    std::string describe() const;
};

struct ContextOptions {
    std::string device;    // index or part of the name; empty: best available
    bool validate = false; // enable VK_LAYER_KHRONOS_validation and count its errors
    bool persistentPipelines = true;  // keep compiled pipelines under $XDG_CACHE_HOME/dacrt
};

class PipelineStore;

class Context {
public:
    explicit Context(const ContextOptions& options);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    std::uint32_t queueFamily() const { return queueFamily_; }
    VkCommandPool commandPool() const { return commandPool_; }
    const DeviceInfo& info() const { return info_; }
    double timestampPeriodNs() const { return timestampPeriodNs_; }
    VkPipelineCache pipelineCache() const;  // every pipeline is created through it
    std::uint32_t memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags wanted) const;

    // Validation messages of error severity seen so far (0 unless validate was set).
    std::uint32_t validationErrors() const;
    const std::vector<std::string>& validationMessages() const;

private:
    void destroy();  // releases the Vulkan handles; safe on a partly built context
    struct Messages;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queueFamily_ = 0;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    DeviceInfo info_;
    double timestampPeriodNs_ = 1.0;
    std::unique_ptr<Messages> messages_;
    std::unique_ptr<PipelineStore> store_;
};

// Every device of every installed driver, in enumeration order. Throws InputError if there
// is no Vulkan driver at all.
std::vector<DeviceInfo> listDevices();

// The device a Context opens for `choice` (ContextOptions::device): empty, the best by type
// (discrete, integrated, virtual, CPU, other; the first of equals); digits, that index; else
// the first whose name contains it. Throws InputError listing the choices when none matches.
std::uint32_t chooseDevice(const std::vector<DeviceInfo>& devices, const std::string& choice);

}  // namespace dacrt::gpu
