#pragma once
// The SPIR-V of shaders/*.comp, compiled by glslang at build time and linked into the binary.
#include <cstdint>
#include <span>

namespace dacrt::gpu {

std::span<const std::uint32_t> dacrtKernelSpirv();    // shaders/dacrt.comp
std::span<const std::uint32_t> secondarySpirv();      // shaders/secondary.comp
std::span<const std::uint32_t> workgroupTestSpirv();  // shaders/workgroup_test.comp
std::span<const std::uint32_t> rayQuerySpirv();       // shaders/rayquery.comp

}  // namespace dacrt::gpu
