#pragma once
// The gpu backend: the parallel scheme's division on the host, Step 1 and the transfer
// rounds as compute dispatches (one workgroup per work item) recorded in one command buffer.
#include <map>
#include <memory>
#include <vector>

#include "cpu_tracers.hpp"
#include "scene_division.hpp"
#include "trace_types.hpp"
#include "vk_context.hpp"
#include "vk_resources.hpp"

namespace dacrt {

struct GpuTuning {
    std::uint32_t workgroupSize = 0;  // 0: the device's default (defaultWorkgroupSize)
    std::uint32_t rayGroups = 0;      // 0: the device's default (defaultRayGroups)
};

// Compiled pipelines kept across frames (an orbit, a benchmark), one per set of
// specialization constants: creating one costs about 40 ms on lavapipe.
class PipelineCache {
public:
    explicit PipelineCache(vk::Context& context) : context_(context) {}
    vk::ComputePipeline& get(const std::vector<std::uint32_t>& specialization);

private:
    vk::Context& context_;
    std::map<std::vector<std::uint32_t>, std::unique_ptr<vk::ComputePipeline>> pipelines_;
};

// Loop iterations one slice of a work item may spend: llvmpipe's loop limiter, 0 elsewhere.
std::uint32_t loopBudgetOf(const vk::DeviceInfo& device);

// Per-device defaults, chosen by measurement (docs/gpu.md): a CPU device such as lavapipe
// runs a workgroup on one thread, SIMD across invocations, so one subgroup per workgroup (no
// shared-memory barrier at all), widened only as far as the loop budget needs for the
// largest region; a GPU wants wider workgroups.
std::uint32_t defaultWorkgroupSize(const vk::DeviceInfo& device, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles);

// Ray groups: each region's rays split into `groups` consecutive runs (rays are in pixel
// order, so these are bands of the image), each with its own copy of the region's triangle
// ids, so that the groups of a region are separate work items that run at once and finish
// at different times, which evens out the load of the workgroups. Region k's group g is
// slot k * groups + g; the ray ids are unchanged. groupRegions gives the slots' table
// (InputError if the triangle ids would overflow 32 bits), groupTriangleIds the copies in
// slot order; they are apart so that the plan is checked before the copies are made.
std::vector<Region> groupRegions(const Division& division, std::uint32_t groups);
std::vector<std::uint32_t> groupTriangleIds(const Division& division, std::uint32_t groups);

// Whether every ray has the first ray's origin and tmin, bit for bit (primary rays do): the
// kernel then takes them from push constants instead of loading them per ray.
bool raysShareStart(const std::vector<Ray>& rays);

// Ray groups per region when --ray-groups is not given.
std::uint32_t defaultRayGroups(const vk::DeviceInfo& device, unsigned regions);

// Regions when --regions is not given.
unsigned defaultGpuRegions(const vk::DeviceInfo& device);

TraceResult traceGpu(const FrameGeometry& geometry, const TraceOptions& options, const GpuTuning& tuning,
                     vk::Context& context, ThreadPool& pool, const PlanHook& onPlan = {},
                     PipelineCache* pipelines = nullptr);

}  // namespace dacrt
