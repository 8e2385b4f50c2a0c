#pragma once
// The devices command: the processor with its SIMD kernels, and the Vulkan devices with the
// limits that matter here.

namespace dacrt {

// Prints them to stdout; returns the exit code. Throws InputError when no Vulkan driver is
// installed (after the processor's line).
int runDevices();

}  // namespace dacrt
