#pragma once
// What this machine offers dacrt: its processor with the SIMD instruction sets the cpu
// backends' kernels can run, and every Vulkan device (the gpu and rayquery backends'
// --device choices) with the limits that bound a trace there.
#include <cstdint>
#include <string>
#include <vector>

namespace dacrt {

struct CpuDevice {
    std::string model;                     // "model name" of /proc/cpuinfo with family and model; "" where none
    std::string simdTarget;                // the instruction set the kernels run now ("AVX3" is AVX-512)
    std::vector<std::string> simdTargets;  // every one this binary holds that the machine runs, best first
    std::string description;               // the line `dacrt devices` prints for it, newline included
};

// What a Vulkan device is and the limits that bound a trace there (the gpu layer's own
// description of a device extends it).
struct VulkanDeviceProperties {
    std::uint32_t index = 0;  // in enumeration order: what a numeric --device names
    std::string name;
    std::string driver;       // driver name and info
    std::string apiVersion;
    std::vector<std::string> heaps;  // "N MiB (device-local)"
    std::uint64_t maxStorageBufferRange = 0;
    std::uint64_t maxMemoryAllocationSize = 0;
    std::uint64_t deviceLocalBytes = 0;  // the largest device-local heap (else the largest heap)
    std::uint32_t maxComputeSharedMemorySize = 0;
    std::uint32_t maxComputeWorkGroupInvocations = 0;
    std::uint32_t maxComputeWorkGroupSizeX = 0;
    std::uint32_t maxComputeWorkGroupCountX = 0;
    std::uint32_t maxPerStageStorageBuffers = 0;
    std::uint32_t subgroupSize = 0;
    bool subgroupOperations = false;  // compute-stage arithmetic and shuffle operations (the gpu kernel's)
    bool fullSubgroups = false;       // VK_EXT_subgroup_size_control's computeFullSubgroups
    bool timestamps = false;
    // The bufferDeviceAddress feature (Vulkan 1.2): the gpu backend reaches arrays larger than
    // maxStorageBufferRange by device address (docs/gpu.md).
    bool bufferDeviceAddress = false;
    // VK_KHR_acceleration_structure, VK_KHR_ray_query and buffer device addresses, with their
    // features, on Vulkan 1.2 or later: what the rayquery backend needs. Otherwise, what lacks.
    bool rayQuery = false;
    std::string rayQueryMissing;
    // VK_KHR_shader_clock's shaderSubgroupClock: what the gpu kernel's stage clocks read
    // (GpuTuning::stageClocks, --stage-clocks).
    bool subgroupClock = false;
};

struct VulkanDevice : VulkanDeviceProperties {
    std::string type;         // as vulkan.hpp names it: DiscreteGpu, IntegratedGpu, VirtualGpu, Cpu, Other
    std::string description;  // the lines `dacrt devices` prints for it, newlines included
};

struct MachineDevices {
    CpuDevice cpu;
    std::vector<VulkanDevice> vulkan;  // every device of every installed driver, in enumeration order
    // Why no Vulkan device could be listed (no Vulkan driver installed); "" when they were
    // (`vulkan` may still be empty: a driver without devices).
    std::string vulkanUnavailable;
};

// The processor and the Vulkan devices. Does not throw for want of Vulkan: that is told by
// vulkanUnavailable. A device's failure while it is described throws.
MachineDevices listDevices();

}  // namespace dacrt
