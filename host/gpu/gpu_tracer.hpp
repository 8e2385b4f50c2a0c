#pragma once
// The gpu backend: the parallel scheme's division on the host, Step 1 and the transfer
// rounds as compute dispatches (one workgroup per work item) recorded in one command buffer.
#include <cstdint>
#include <memory>

#include <dacrt/backend_tuning.hpp>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"
#include "cpu/secondary_rays.hpp"
#include "cpu/trace_result.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu/resident_triangles.hpp"

namespace dacrt {

// The phase in which pipelines are created and compiled (first use in a process; drivers that
// cache compiled pipelines make it short afterwards): reported apart from the frame's time.
inline constexpr const char* kPipelinePhase = "pipeline compile";

// Throws InputError when the options ask for what the kernel does not run: it runs the
// spatial-median split and the exact defaults. traceGpu checks this, and the device.
void checkGpuOptions(const TraceOptions& options);

// What a primary pass leaves on the device for the frame's secondary passes (its rays, hits
// and triangles: never read back and uploaded again). Opaque; made by traceGpu.
struct GpuPassSource;
struct GpuPassSourceDeleter {
    void operator()(GpuPassSource* source) const;
};
using GpuPassSourcePtr = std::unique_ptr<GpuPassSource, GpuPassSourceDeleter>;

// Traces one frame on the context's device. Pipelines come from `pipelines` when given (kept
// across frames), else are made for this frame alone.
// With `resident` (and options.skips.uploads), the triangles and bounds stay on the device
// between frames of the same FrameGeometry::trianglesVersion. With `keep`, the frame's device
// buffers are kept there for traceGpuSecondary.
TraceResult traceGpu(const FrameGeometry& geometry, const TraceOptions& options, const GpuTuning& tuning,
                     gpu::Context& context, ThreadPool& pool, const PlanHook& onPlan = {},
                     gpu::PipelineCache* pipelines = nullptr, gpu::ResidentTriangles* resident = nullptr,
                     GpuPassSourcePtr* keep = nullptr);

// A secondary pass of the frame `source` kept: its rays made from the primary hits and binned
// to the regions on the device (shaders/secondary.comp), then traced by the same DACRT kernel
// for any hit. `frame` is the primary frame before its triangle skips (secondary rays may hit
// any triangle). Returns one hit per slot (SecondaryPass: primary ray x raysPerHit), with
// kNotTracedPrim where the surface sends no ray, as hitsPerSlot gives on the host.
TraceResult traceGpuSecondary(GpuPassSource& source, const FrameGeometry& frame, const SecondaryPass& pass,
                              const TraceOptions& options, const GpuTuning& tuning, gpu::Context& context,
                              ThreadPool& pool, const PlanHook& onPlan = {}, gpu::PipelineCache* pipelines = nullptr);

}  // namespace dacrt
