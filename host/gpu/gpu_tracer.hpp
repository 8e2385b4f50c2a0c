#pragma once
// The gpu backend: the parallel scheme's division on the host, Step 1 and the transfer
// rounds as compute dispatches (one workgroup per work item) recorded in one command buffer.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <dacrt/backend_tuning.hpp>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"
#include "cpu/secondary_rays.hpp"
#include "cpu/trace_result.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu/ray_packets.hpp"
#include "gpu/buffer_arena.hpp"
#include "gpu/resident_triangles.hpp"

namespace dacrt {


// Throws InputError when the options ask for what the kernel does not run: it runs the
// spatial-median split and the exact defaults. GpuTracer checks this, and the device.
void checkGpuOptions(const TraceOptions& options);

// What a primary pass leaves on the device for the frame's secondary passes (its rays, hits
// and triangles: never read back and uploaded again). Opaque; made by GpuTracer::trace.
struct GpuPassSource;
struct GpuPassSourceDeleter {
    void operator()(GpuPassSource* source) const;
};
using GpuPassSourcePtr = std::unique_ptr<GpuPassSource, GpuPassSourceDeleter>;

// How many slots (primary rays x rays per hit) one secondary pass holds on the device, and
// what holds no more: without buffer device addresses, the rays one binding holds; else the
// ray ids' 32-bit indices, and half the device memory that `source`'s buffers (null: none)
// leave, the other half for the pass's triangle ids, work items and stacks, which its plan
// then checks exactly. A pass of more slots runs in batches of samples (library/frame_passes).
struct PassCapacity {
    std::uint64_t slots = 0;
    std::string limit;  // "one binding of rays (maxStorageBufferRange, ...)", ...
};
PassCapacity secondaryPassCapacity(const GpuPassSource* source, const gpu::BufferLimits& limits);

// Traces frames on the context's device with one set of options: each stage of a frame (the
// division, the plan, the upload, the pipelines, the dispatch rounds, the readback) is a
// method, run in that order by trace() and traceSecondary().
class GpuTracer {
public:
    // Pipelines come from `pipelines` when given (kept across frames), else are made for this
    // tracer alone. With `resident` (and options.skips.uploads), the triangles and bounds stay
    // on the device between frames of the same FrameGeometry::trianglesVersion. With `arena`,
    // every other buffer is leased from it, and kept there for the next frame.
    // Throws InputError for options the kernel does not run (checkGpuOptions).
    GpuTracer(gpu::Context& context, ThreadPool& pool, const TraceOptions& options, const GpuTuning& tuning,
              gpu::PipelineCache* pipelines = nullptr, gpu::ResidentTriangles* resident = nullptr,
              gpu::BufferArena* arena = nullptr);
    ~GpuTracer();

    // Traces one frame. With `keep`, the frame's device buffers are kept there for
    // traceSecondary.
    TraceResult trace(const FrameGeometry& geometry, const PlanHook& onPlan = {}, GpuPassSourcePtr* keep = nullptr);

    // A secondary pass of the frame `source` kept: its rays made from the primary hits and binned
    // to the regions on the device (shaders/secondary.comp), then traced by the same DACRT kernel
    // for any hit. `frame` is the primary frame before its triangle skips (secondary rays may hit
    // any triangle). Returns one hit per slot (SecondaryPass: primary ray x raysPerHit), with
    // kNotTracedPrim where the surface sends no ray, as hitsPerSlot gives on the host.
    TraceResult traceSecondary(GpuPassSource& source, const FrameGeometry& frame, const SecondaryPass& pass,
                               const PlanHook& onPlan = {});

private:
    struct Frame;  // what a frame's (or a pass's) stages hand each other

    // A primary frame's stages.
    void divide(Frame& frame);
    static void setPackets(Frame& frame, std::optional<gpu::RayPackets> packets);
    void planMemory(Frame& frame) const;
    void planBuffers(Frame& frame) const;
    void planBufferReuse(Frame& frame) const;
    void checkStageClocks(const gpu::DacrtBufferPlan& buffers) const;
    void upload(Frame& frame) const;
    void uploadPackets(Frame& frame) const;
    void dispatch(Frame& frame) const;
    void readBack(Frame& frame) const;
    // A secondary pass's own stages.
    void divideForSecondaryRays(GpuPassSource& source, const FrameGeometry& frame, TraceResult& result) const;
    void planPass(Frame& frame, const GpuPassSource& source, const SecondaryPass& pass) const;
    void uploadPass(Frame& frame, const GpuPassSource& source) const;
    void dispatchPass(Frame& frame, const GpuPassSource& source, const SecondaryPass& pass) const;
    // Shared by both.
    TraceResult startResult() const;
    std::uint64_t stackSlots(std::uint64_t workItems) const;
    // What the rays of a trace share, which the kernel then takes once (DACRT_SPEC_SHARED_*).
    struct KernelRays {
        bool sharedStart = false;    // origin and tmin (push rayOrigin, rayTmin)
        bool anyHit = false;
        bool sharedSegment = false;  // any hit: tmin and tmax (push rayTmin, rayTmax)
    };
    void compileKernel(Frame& frame, const KernelRays& rays) const;

    gpu::Context& context_;
    ThreadPool& pool_;
    TraceOptions options_;
    GpuTuning tuning_;
    gpu::BufferLimits limits_;  // what bounds each buffer: the device's limits or the tuning's caps
    std::unique_ptr<gpu::PipelineCache> ownPipelines_;  // without `pipelines`: this tracer's
    gpu::PipelineCache& pipelines_;
    gpu::ResidentTriangles* resident_;
    gpu::BufferArena* arena_;
};

}  // namespace dacrt
