#pragma once
// What the gpu backend chooses per device when the caller leaves it open, by measurement
// (docs/gpu.md), and the limits that bound those choices.
#include <cstdint>

#include "gpu/context.hpp"

namespace dacrt::gpu {

// Loop iterations one slice of a work item may spend: llvmpipe's loop limiter, 0 elsewhere.
std::uint32_t loopBudgetOf(const DeviceInfo& device);

// The widest workgroup the kernel takes: the device's limits, and at most as many subgroups
// as one subgroup has lanes (workgroupExclusiveSum sums the subgroup totals in one subgroup).
std::uint32_t widestWorkgroup(const DeviceInfo& device);

// A CPU device such as lavapipe runs a workgroup on one thread, SIMD across invocations, so
// one subgroup per workgroup (no shared-memory barrier at all), widened only as far as the
// loop budget needs for the largest region; a GPU wants wider workgroups.
std::uint32_t defaultWorkgroupSize(const DeviceInfo& device, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles);

// Ray groups per region (see groupRegions in gpu/work_plan.hpp).
std::uint32_t defaultRayGroups(const DeviceInfo& device, unsigned regions);

// Regions (sub-scenes).
unsigned defaultGpuRegions(const DeviceInfo& device);

}  // namespace dacrt::gpu
