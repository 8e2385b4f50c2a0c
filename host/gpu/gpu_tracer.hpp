#pragma once
// The gpu backend: the parallel scheme's division on the host, Step 1 and the transfer
// rounds as compute dispatches (one workgroup per work item) recorded in one command buffer.
#include <cstdint>

#include "core/thread_pool.hpp"
#include "dacrt/frame_geometry.hpp"
#include "dacrt/memory_plan.hpp"
#include "dacrt/options.hpp"
#include "dacrt/trace_result.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu/resident_triangles.hpp"

namespace dacrt {

// The phase in which pipelines are created and compiled (first use in a process; drivers that
// cache compiled pipelines make it short afterwards): reported apart from the frame's time.
inline constexpr const char* kPipelinePhase = "pipeline compile";

struct GpuTuning {
    std::uint32_t workgroupSize = 0;  // 0: the device's default (gpu::defaultWorkgroupSize)
    std::uint32_t rayGroups = 0;      // 0: the device's default (gpu::defaultRayGroups)
};

// Throws InputError when the options ask for what the kernel does not run: it runs the
// spatial-median split and the exact defaults. traceGpu checks this, and the device.
void checkGpuOptions(const TraceOptions& options);

// Traces one frame on the context's device. Pipelines come from `pipelines` when given (kept
// across frames), else are made for this frame alone.
// With `resident` (and options.skips.uploads), the triangles and bounds stay on the device
// between frames of the same FrameGeometry::trianglesVersion.
TraceResult traceGpu(const FrameGeometry& geometry, const TraceOptions& options, const GpuTuning& tuning,
                     gpu::Context& context, ThreadPool& pool, const PlanHook& onPlan = {},
                     gpu::PipelineCache* pipelines = nullptr, gpu::ResidentTriangles* resident = nullptr);

}  // namespace dacrt
