#include "gpu/embedded_shaders.hpp"

#include "dacrt.spv.h"
#include "dacrt_addressed.spv.h"
#include "dacrt_clocks.spv.h"
#include "rayquery.spv.h"
#include "secondary.spv.h"
#include "secondary_addressed.spv.h"
#include "workgroup_test.spv.h"

namespace dacrt::gpu {

std::span<const std::uint32_t> dacrtKernelSpirv() { return {dacrt_spv, sizeof(dacrt_spv) / sizeof(dacrt_spv[0])}; }

std::span<const std::uint32_t> secondarySpirv() {
    return {secondary_spv, sizeof(secondary_spv) / sizeof(secondary_spv[0])};
}

std::span<const std::uint32_t> dacrtKernelAddressedSpirv() {
    return {dacrt_addressed_spv, sizeof(dacrt_addressed_spv) / sizeof(dacrt_addressed_spv[0])};
}

std::span<const std::uint32_t> dacrtKernelClocksSpirv() {
    return {dacrt_clocks_spv, sizeof(dacrt_clocks_spv) / sizeof(dacrt_clocks_spv[0])};
}

std::span<const std::uint32_t> secondaryAddressedSpirv() {
    return {secondary_addressed_spv, sizeof(secondary_addressed_spv) / sizeof(secondary_addressed_spv[0])};
}

std::span<const std::uint32_t> workgroupTestSpirv() {
    return {workgroup_test_spv, sizeof(workgroup_test_spv) / sizeof(workgroup_test_spv[0])};
}

std::span<const std::uint32_t> rayQuerySpirv() { return {rayquery_spv, sizeof(rayquery_spv) / sizeof(rayquery_spv[0])}; }

}  // namespace dacrt::gpu
