#include "gpu/device_defaults.hpp"

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace dacrt::gpu {

namespace {

bool isLlvmpipe(const DeviceInfo& device) { return device.driver.find("llvmpipe") != std::string::npos; }

// Mesa's major version from the driver's description ("llvmpipe Mesa 25.0.7 ..."), 0 if none.
int mesaMajorOf(const DeviceInfo& device) {
    const std::size_t mesa = device.driver.find("Mesa ");
    return mesa == std::string::npos ? 0 : std::atoi(device.driver.c_str() + mesa + 5);
}

}  // namespace

std::uint32_t loopBudgetOf(const DeviceInfo& device) {
    // llvmpipe in Mesa 22.3.6 stops all loops of an invocation after 65535 iterations in all;
    // keep a margin for the few loops the kernel's cost estimates round down. Mesa 25.0.7's
    // does not (measured, docs/gpu.md: the whole Bunny as one work item in one slice, the
    // kernel's limiter probe silent); versions between are treated as the older one.
    if (!isLlvmpipe(device)) return 0;
    return mesaMajorOf(device) >= 25 ? 0u : 40000u;
}

bool takesCpuDefaults(const DeviceInfo& device, GpuProfile profile) {
    return profile == GpuProfile::Auto ? device.isCpu() : profile == GpuProfile::Cpu;
}

std::uint32_t widestWorkgroup(const DeviceInfo& device) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    return std::min({device.maxComputeWorkGroupInvocations, device.maxComputeWorkGroupSizeX, subgroup * subgroup});
}

double stepWorkgroupNeed(const DeviceInfo& device, std::uint32_t largestRegionRays, std::uint32_t largestRegionTriangles) {
    const std::uint32_t budget = loopBudgetOf(device);
    if (!budget) return 0.0;
    // The largest single step (a split of the biggest region, then its final partition) must
    // fit one slice: about (2 (rays + triangles) + 2 rays) / (4 size) iterations, a partition
    // step taking four ids per invocation (kIdsPerInvocation).
    return (4.0 * largestRegionRays + 2.0 * largestRegionTriangles) / (4.0 * 0.8 * budget);
}

std::uint32_t defaultWorkgroupSize(const DeviceInfo& device, GpuProfile profile, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = widestWorkgroup(device);
    std::uint32_t size = takesCpuDefaults(device, profile) ? subgroup : std::max(64u, subgroup);
    const double needed = stepWorkgroupNeed(device, largestRegionRays, largestRegionTriangles);
    while (size < widest && double(size) < needed) size *= 2;
    return std::min(size, widest);
}

std::uint32_t defaultRayGroups(const DeviceInfo& device, GpuProfile profile, unsigned regions) {
    // A CPU device under the loop limiter: two per region, because a dispatch of slices lasts
    // as long as its longest slice and more work items even them out (docs/gpu.md). Without
    // the limiter each work item runs to its end in one dispatch, and a second group only
    // filters the region's triangles twice near the root (Mesa 25.0.7: one group 5.5% faster
    // on the Dragon, 1.7% on the Bunny, docs/benchmarks.md). A GPU: enough groups for
    // kDiscreteStep1WorkItems in Step 1, each a copy of its region's triangle ids (docs/gpu.md,
    // "The gpu profiles": the Dragon at 1920x1080, counted by the kernel's cost model).
    if (takesCpuDefaults(device, profile)) return loopBudgetOf(device) ? 2u : 1u;
    return std::clamp((kDiscreteStep1WorkItems + regions - 1u) / regions, 1u, kMostDefaultRayGroups);
}

bool runsSubgroupsInLockstep(const DeviceInfo& device) { return isLlvmpipe(device); }

bool dropsBarriers(const DeviceInfo& device, std::uint32_t workgroupSize) {
    return runsSubgroupsInLockstep(device) && workgroupSize == device.subgroupSize;
}

std::uint32_t defaultLeafOverSplit(const DeviceInfo& device, GpuProfile profile) {
    return takesCpuDefaults(device, profile) ? 0u : kDiscreteLeafOverSplit;
}

KernelLeafRule kernelLeafRule(const DacrtOptions& given, const GpuTuning& tuning, const DeviceInfo& device) {
    const bool limitsGiven = given.rayLimit != 0 || given.triLimit != 0;
    KernelLeafRule rule;
    rule.leafBalance = tuning.leafBalance.value_or(
        takesCpuDefaults(device, tuning.profile) && !limitsGiven ? kCpuProfileLeafBalance : 0u);
    const std::uint32_t unsetLimit = rule.leafBalance != 0 ? 1u : kGpuLeafLimit;
    rule.rayLimit = given.rayLimit != 0 ? given.rayLimit : unsetLimit;
    rule.triLimit = given.triLimit != 0 ? given.triLimit : unsetLimit;
    return rule;
}

bool balancesRayGroups(const DeviceInfo& device, GpuProfile profile) {
    return !takesCpuDefaults(device, profile) && loopBudgetOf(device) == 0;
}

unsigned defaultGpuRegions(const DeviceInfo& device, GpuProfile profile) {
    // A CPU device runs one workgroup per thread: one region per core, as for the cpu backend,
    // measured best on lavapipe (docs/benchmarks.md: 2 regions beat 16 by 35% on the Bunny
    // and 17% on the Dragon). A GPU wants thousands of work items: 64 regions halved the
    // longest chain of dependent work items of 16 (docs/gpu.md, "The gpu profiles").
    return takesCpuDefaults(device, profile) ? std::max(1u, std::thread::hardware_concurrency()) : kDiscreteRegions;
}

}  // namespace dacrt::gpu
