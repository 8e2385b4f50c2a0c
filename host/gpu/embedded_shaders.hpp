#pragma once
// The SPIR-V of shaders/*.comp, compiled by glslang at build time and linked into the binary.
#include <cstdint>
#include <span>

namespace dacrt::gpu {

std::span<const std::uint32_t> dacrtKernelSpirv();    // shaders/dacrt.comp
std::span<const std::uint32_t> secondarySpirv();      // shaders/secondary.comp
// The same two kernels with DACRT_ADDRESSED: the large arrays by device address, in chunks.
std::span<const std::uint32_t> dacrtKernelAddressedSpirv();
std::span<const std::uint32_t> secondaryAddressedSpirv();
// The kernel with its stage clocks (DACRT_STAGE_CLOCKS): needs the shaderSubgroupClock feature.
std::span<const std::uint32_t> dacrtKernelClocksSpirv();
std::span<const std::uint32_t> workgroupTestSpirv();  // shaders/workgroup_test.comp
std::span<const std::uint32_t> rayQuerySpirv();       // shaders/rayquery.comp

}  // namespace dacrt::gpu
