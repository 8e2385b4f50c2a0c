#include "cmd/devices.hpp"

#include <iostream>

#include <dacrt/devices.hpp>
#include <dacrt/errors.hpp>

#include "app/exit_codes.hpp"

namespace dacrt {

int runDevices() {
    const MachineDevices machine = listDevices();
    std::cout << machine.cpu.description;
    if (!machine.vulkanUnavailable.empty()) throw InputError(machine.vulkanUnavailable);
    if (machine.vulkan.empty()) std::cout << "no Vulkan devices\n";
    for (const VulkanDevice& d : machine.vulkan) std::cout << d.description;
    return int(kExitSuccess);
}

}  // namespace dacrt
