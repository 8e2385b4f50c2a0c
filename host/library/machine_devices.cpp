// The public listDevices: the processor with its SIMD kernels and the Vulkan devices, as
// `dacrt devices` prints them.
#include <dacrt/devices.hpp>
#include <dacrt/errors.hpp>

#include "core/cpu_model.hpp"
#include "cpu/simd_kernels.hpp"
#include "gpu/context.hpp"

namespace dacrt {
namespace {

CpuDevice describeCpu() {
    CpuDevice cpu{.model = cpuModelName(), .simdTarget = simd::activeTarget(), .simdTargets = simd::availableTargets(), .description = ""};
    std::string targets;
    for (const std::string& t : cpu.simdTargets) targets += " " + t;
    cpu.description = "cpu: " + cpu.model + "; SIMD kernels run " + cpu.simdTarget + " (this binary can run:" + targets +
                      "; DACRT_SIMD_TARGET chooses)\n";
    return cpu;
}

VulkanDevice publicDevice(const gpu::DeviceInfo& d) {
    return {static_cast<const VulkanDeviceProperties&>(d), d.typeName(), d.describe()};
}

}  // namespace

MachineDevices listDevices() {
    MachineDevices machine{.cpu = describeCpu(), .vulkan = {}, .vulkanUnavailable = ""};
    try {
        for (const gpu::DeviceInfo& d : gpu::listDevices()) machine.vulkan.push_back(publicDevice(d));
    } catch (const InputError& e) {  // no Vulkan driver: gpu::listDevices' only InputError
        machine.vulkanUnavailable = e.what();
    }
    return machine;
}

}  // namespace dacrt
