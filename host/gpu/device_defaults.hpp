#pragma once
// What the gpu backend chooses per device when the caller leaves it open, by measurement
// (docs/gpu.md), and the limits that bound those choices.
#include <cstdint>

#include <dacrt/backend_tuning.hpp>
#include <dacrt/options.hpp>

#include "gpu/context.hpp"

namespace dacrt::gpu {

// The discrete profile's shape (docs/gpu.md, "The gpu profiles"): Step 1 gets at
// least kDiscreteStep1WorkItems work items, kDiscreteRegions regions times their ray groups
// (at most kMostDefaultRayGroups, the triangle ids being copied once per group).
inline constexpr unsigned kDiscreteRegions = 64;
inline constexpr std::uint32_t kDiscreteStep1WorkItems = 2048;
inline constexpr std::uint32_t kMostDefaultRayGroups = 64;

// Whether the profile gives this device a CPU device's defaults (GpuProfile::Auto: if it is one).
bool takesCpuDefaults(const DeviceInfo& device, GpuProfile profile);

// Loop iterations one slice of a work item may spend: llvmpipe's loop limiter, 0 elsewhere.
std::uint32_t loopBudgetOf(const DeviceInfo& device);

// The widest workgroup the kernel takes: the device's limits, and at most as many subgroups
// as one subgroup has lanes (workgroupExclusiveSum sums the subgroup totals in one subgroup).
std::uint32_t widestWorkgroup(const DeviceInfo& device);

// The workgroup size (invocations) the largest single step of a frame whose largest region
// holds these rays and triangles needs to fit one slice of the loop budget; 0 without one.
double stepWorkgroupNeed(const DeviceInfo& device, std::uint32_t largestRegionRays, std::uint32_t largestRegionTriangles);

// A CPU device such as lavapipe runs a workgroup on one thread, SIMD across invocations, so
// one subgroup per workgroup (no shared-memory barrier at all), widened only as far as the
// loop budget needs for the largest region; a GPU wants wider workgroups.
std::uint32_t defaultWorkgroupSize(const DeviceInfo& device, GpuProfile profile, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles);

// Ray groups per region (see groupRegions in gpu/work_plan.hpp).
std::uint32_t defaultRayGroups(const DeviceInfo& device, GpuProfile profile, unsigned regions);

// The discrete profile's leaf rule (shaders/dacrt.comp, leafCostsMoreThanSplits): a node whose
// leaf would cost more than this many splits splits on. Measured on the Dragon at 1920x1080
// (docs/gpu.md, "The gpu profiles"): 8 and 16 gave the least work and the shortest chain (2,
// 4 and 32 more); under the cpu profile the rule stays off (0), the kernel as before.
inline constexpr std::uint32_t kDiscreteLeafOverSplit = 8;
std::uint32_t defaultLeafOverSplit(const DeviceInfo& device, GpuProfile profile);

// What makes a node a leaf in the kernel: fewer rays than rayLimit, fewer triangles than
// triLimit, or the leaf balance (shaders/leaf_rule.glsl; 0: off).
struct KernelLeafRule {
    std::uint32_t rayLimit = 0;
    std::uint32_t triLimit = 0;
    std::uint32_t leafBalance = 0;
};
// The rule for these options (their leaf limits as the caller gave them, 0 where not) and
// this tuning: the leaf balance as given, else kCpuProfileLeafBalance under the cpu profile
// where the caller gave neither leaf limit (on lavapipe a partitioned id costs about as much
// as a ray/triangle test or two, so the best leaves follow the product of the counts, which
// two limits cannot express) and 0 elsewhere. Under the balance a limit not given is off (1);
// without it, kGpuLeafLimit.
KernelLeafRule kernelLeafRule(const DacrtOptions& given, const GpuTuning& tuning, const DeviceInfo& device);

// Whether the device runs each subgroup as the lanes of one SIMD thread, whose invocations cannot
// be out of step: llvmpipe does (lavapipe compiles a subgroup into one vector loop of its
// thread); a GPU's lanes may diverge.
bool runsSubgroupsInLockstep(const DeviceInfo& device);
// Whether the kernel, in workgroups of workgroupSize invocations, specializes to one without
// execution barriers (kLockstepSubgroups): where the workgroup is one subgroup that the device
// runs in lockstep.
bool dropsBarriers(const DeviceInfo& device, std::uint32_t workgroupSize);

// Whether Step 1's ray groups are cut to equal estimated cost (gpu/ray_cost_estimate.hpp,
// costedRayGroups) rather than to equal ray counts: the discrete profile's many groups, whose
// costs otherwise follow what each band of the image meets. Not under a loop limiter, where
// items that take turns on a shared copy of triangle ids wait for each other slice by slice,
// one dispatch each (docs/gpu.md, "The gpu profiles").
bool balancesRayGroups(const DeviceInfo& device, GpuProfile profile);

// Regions (sub-scenes).
unsigned defaultGpuRegions(const DeviceInfo& device, GpuProfile profile);

}  // namespace dacrt::gpu
