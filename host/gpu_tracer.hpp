#pragma once
// The gpu backend: the parallel scheme's division on the host, Step 1 and the transfer
// rounds as compute dispatches (one workgroup per work item) recorded in one command buffer.
#include <map>
#include <memory>
#include <vector>

#include "cpu_tracers.hpp"
#include "trace_types.hpp"
#include "vk_context.hpp"
#include "vk_resources.hpp"

namespace dacrt {

struct GpuTuning {
    std::uint32_t workgroupSize = 0;  // 0: the device's default (defaultWorkgroupSize)
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

// Whether every ray has the first ray's origin and tmin, bit for bit (primary rays do): the
// kernel then takes them from push constants instead of loading them per ray.
bool raysShareStart(const std::vector<Ray>& rays);

// Regions when --regions is not given.
unsigned defaultGpuRegions(const vk::DeviceInfo& device);

TraceResult traceGpu(const FrameGeometry& geometry, const TraceOptions& options, const GpuTuning& tuning,
                     vk::Context& context, ThreadPool& pool, const PlanHook& onPlan = {},
                     PipelineCache* pipelines = nullptr);

}  // namespace dacrt
