#include "gpu/device_defaults.hpp"

#include <algorithm>
#include <thread>

namespace dacrt::gpu {

std::uint32_t loopBudgetOf(const DeviceInfo& device) {
    // llvmpipe stops all loops of an invocation after 65535 iterations in all; keep a margin
    // for the few loops the kernel's cost estimates round down.
    return device.driver.find("llvmpipe") != std::string::npos ? 40000u : 0u;
}

std::uint32_t widestWorkgroup(const DeviceInfo& device) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    return std::min({device.maxComputeWorkGroupInvocations, device.maxComputeWorkGroupSizeX, subgroup * subgroup});
}

std::uint32_t defaultWorkgroupSize(const DeviceInfo& device, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = widestWorkgroup(device);
    std::uint32_t size = device.isCpu() ? subgroup : std::max(64u, subgroup);
    if (const std::uint32_t budget = loopBudgetOf(device)) {
        // The largest single step (a split of the biggest region, then its final partition)
        // must fit one slice: about (2 (rays + triangles) + 2 rays) / (4 size) iterations, a
        // partition step taking four ids per invocation (kIdsPerInvocation).
        const double needed = (4.0 * largestRegionRays + 2.0 * largestRegionTriangles) / (4.0 * 0.8 * budget);
        while (size < widest && double(size) < needed) size *= 2;
    }
    return std::min(size, widest);
}

std::uint32_t defaultRayGroups(const DeviceInfo& device, unsigned regions) {
    // A CPU device: two per region, so that a thread whose work item ends early finds
    // another (docs/gpu.md). A GPU: at least 64 work items in Step 1 (unmeasured).
    return device.isCpu() ? 2u : std::max(1u, (64u + regions - 1u) / regions);
}

unsigned defaultGpuRegions(const DeviceInfo& device) {
    // A CPU device runs one workgroup per thread: one region per core, as for the cpu backend,
    // measured best on lavapipe (docs/benchmarks.md: 2 regions beat 16 by 35% on the Bunny
    // and 17% on the Dragon). A GPU wants many work items; 16 is unmeasured there.
    return device.isCpu() ? std::max(1u, std::thread::hardware_concurrency()) : 16u;
}

}  // namespace dacrt::gpu
