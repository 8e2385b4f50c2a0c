#pragma once
// The one place where a backend choice becomes a trace, the engine of the public Tracer
// (tracer.cpp): the request checked against the backend, the devices and pipelines opened
// once, the peers' structures kept from frame to frame, the frame traced, and the validation
// epilogue.
#include <cstdint>
#include <iosfwd>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/made_pass_groups.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"
#include "cpu/pass_cull.hpp"
#include "cpu/ray_grouping.hpp"
#include "cpu/secondary_rays.hpp"
#include "cpu/trace_result.hpp"
#include "gpu/context.hpp"
#include "gpu/gpu_tracer.hpp"
#include "gpu/pipeline_cache.hpp"
#include "library/peer_scenes.hpp"

namespace dacrt {

struct BackendRequest {
    TraceOptions trace;
    // gpu: keep the frame's rays, hits and triangles on the device for traceSecondary.
    bool keepForPasses = false;
    GpuTuning gpuTuning;        // gpu only
    EmbreeOptions embree;       // embree only (threads: the request's)
    RayQueryBuild rayQueryBuild = RayQueryBuild::Dynamic;  // rayquery only
};

// Throws InputError, naming the command-line options, when the request gives a backend an
// option it does not take (the table of cpu/backend_options.hpp) or options that do not combine.
void checkBackendRequest(const BackendRequest& request);

struct DeviceChoice {
    std::string device;     // gpu: index or part of the name; empty: the best device
    bool validate = false;  // gpu: Khronos validation layers, errors counted
};

// Throws InputError when --device or --validate is given but no gpu backend runs.
void checkDeviceChoice(const DeviceChoice& devices, const std::vector<Backend>& backends);

class BackendDispatcher {
public:
    // Opens the Vulkan device now when `backends` includes gpu or rayquery, so that a missing or
    // unmatched device fails before any long work.
    BackendDispatcher(const DeviceChoice& devices, const std::vector<Backend>& backends);
    ~BackendDispatcher();

    // Threads a request runs on: 1 for cpu-seq, else its own count or every core.
    static unsigned threadsOf(const TraceOptions& options);
    ThreadPool& pool(unsigned threads);
    gpu::Context* gpuContext() { return gpu_.get(); }  // null unless gpu or rayquery was asked for
    gpu::PipelineCache* pipelines() { return pipelines_.get(); }
    const gpu::Context* gpuContext() const { return gpu_.get(); }

    // Checks the request (checkBackendRequest), then traces one frame on its backend: for
    // dacrt's backends, after the triangle skips the request allows (triangle_skips.hpp),
    // whose counts open the plan's work lines; for the peers, over the structure they keep for
    // the geometry's scene (PeerScenes: a new frame of it).
    // onProgress is called by the backends that report progress (brute force).
    TraceResult trace(const FrameGeometry& geometry, const BackendRequest& request, const PlanHook& onPlan = {},
                      const ProgressHook& onProgress = {});

    // A secondary pass of the frame the last trace() traced (with request.keepForPasses on
    // gpu): its rays made from the primary hits (on the device for gpu, where the primary pass
    // left them; on the host for the others, and for gpu where it kept nothing or where the
    // pass cull may drop triangles: passCullMayDrop) and traced for any hit by the same
    // backend, over the triangles the pass cull keeps (pass_cull.hpp: those the pass's rays can
    // reach; the peers and the gpu's device-made rays trace every one). `primary` is the frame as
    // given to trace(); the peers trace the structure it left. Returns one hit per slot
    // (hitsPerSlot) and the rays made.
    struct PassTrace {
        TraceResult result;
        std::uint64_t rays = 0;
    };
    PassTrace traceSecondary(const FrameGeometry& primary, const std::vector<Hit>& primaryHits, const SecondaryPass& pass,
                             const BackendRequest& request, const PlanHook& onPlan = {});

    // Several secondary passes of that frame traced as one (cpu backends, --pass-tracing together):
    // each pass's rays made as traceSecondary makes them, merged pixel by pixel (a pixel's rays
    // of every pass together, the passes in their order), traced for any hit in one DACRT, and
    // each hit put back in its pass's slot: one PassTrace per pass, its hits and rays; the
    // trace's plan, counters and phases go with the last pass (the passes share them).
    // Throws InputError where their slots together exceed kMaxSecondarySlots (32-bit ids).
    static constexpr std::size_t kMostPassesTogether = 65536;  // a pass index per ray: 16 bits
    // The passes' slots together (secondarySlots summed).
    static std::uint64_t slotsTogether(const std::vector<SecondaryPass>& passes, std::uint64_t primaryRays);
    std::vector<PassTrace> traceSecondaryTogether(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                                                  const std::vector<SecondaryPass>& passes,
                                                  const BackendRequest& request, const PlanHook& onPlan = {});

    // gpu: how many slots one traceSecondary of the last frame holds on the device
    // (secondaryPassCapacity); unlimited elsewhere.
    PassCapacity secondaryPassCapacity(const BackendRequest& request) const;

    // Frees the peers' structures, the gpu's resident triangles and kept buffers, and the last
    // frame kept for its passes: the next trace makes them again (Tracer::releaseKept).
    void releaseKept();

    std::uint32_t validationErrors() const;
    // Under --validate: prints every validation message; true when there were errors (the
    // command then fails with its validation exit code).
    bool reportValidationErrors(std::ostream& err) const;

private:
    // The trace itself, on the triangles the skips left (dacrt's backends) or on every one.
    TraceResult traceOnBackend(const FrameGeometry& geometry, const BackendRequest& request, const PlanHook& onPlan,
                               const ProgressHook& onProgress, PeerFrame frame);
    // The trace of the triangles `skips` kept, its plan and result opened by skipPlan's lines.
    TraceResult traceAfterSkips(const FrameGeometry& geometry, const TriangleSkips& skips, const MemoryPlan& skipPlan,
                                double skipMs, const BackendRequest& request, const PlanHook& onPlan,
                                const ProgressHook& onProgress);
    // A gpu pass whose rays the device makes from the hits the primary pass left there, over
    // every triangle (the pass cull's lines say why none was dropped).
    PassTrace traceMadeOnDevice(const FrameGeometry& primary, const SecondaryPass& pass, const BackendRequest& request,
                                const PlanHook& onPlan);
    // A secondary pass's rays (host-made) traced as one frame on the request's backend.
    TraceResult tracePassRays(const FrameGeometry& primary, const std::vector<Ray>& rays, const BackendRequest& request,
                              const PlanHook& onPlan);
    // RayGrouping::OctantCalls and Batches: each group of the rays (group k: from groups[k] to
    // groups[k + 1]) traced as a frame of its own after one pass cull over them all, the hits
    // in the rays' order, the counters and phases summed (the plan and division: the first's).
    TraceResult traceGroups(const FrameGeometry& primary, const std::vector<Ray>& rays,
                            const std::vector<std::size_t>& groups, const BackendRequest& request,
                            const PlanHook& onPlan);
    // traceGroups on the cpu backend with more than one worker and group: the groups side by
    // side (`live`: those with rays), each a sequential DACRT on one worker (after traceGroups'
    // pass cull).
    TraceResult traceGroupsSideBySide(const FrameGeometry& primary, const std::vector<Ray>& rays,
                                      const std::vector<std::size_t>& groups,
                                      const std::vector<std::size_t>& live, const BackendRequest& request,
                                      const PlanHook& onPlan, const MemoryPlan& cullPlan, double cullMs);
    // A secondary pass's rays on dacrt's backends, over the triangles the pass cull keeps.
    TraceResult traceCulled(const FrameGeometry& pass, const BackendRequest& request, const PlanHook& onPlan);

    DeviceChoice devices_;
    std::map<unsigned, std::unique_ptr<ThreadPool>> pools_;
    std::unique_ptr<gpu::Context> gpu_;
    std::unique_ptr<gpu::PipelineCache> pipelines_;
    std::unique_ptr<gpu::ResidentTriangles> resident_;  // gpu: the triangles kept on the device
    std::unique_ptr<gpu::BufferArena> arena_;           // gpu: every other buffer, kept for the next frame
    GroupingBuffers grouping_;                          // cpu: a pass's rays grouped (--ray-grouping)
    std::vector<std::vector<Ray>> workerGroups_;        // cpu: each worker's group (traceGroupsSideBySide)
    std::vector<MadeGroupBuffers> madeGroups_;          // cpu: each worker's made group (traceMadeSideBySide)
    GpuPassSourcePtr passSource_;                       // gpu: the last frame kept for its secondary passes
    PeerScenes peers_;                                  // embree, rayquery: their structures
    PassCull passCull_;                                 // the last pass's cull, its buffers reused
};

}  // namespace dacrt
