#pragma once
// The peers' structures a tracer keeps from trace to trace, as Embree's and Vulkan's users keep
// them: built at a scene's first trace, then followed as each build mode follows a dynamic
// scene's frames (public <dacrt/tracer.hpp> says what each trace costs).
#include <cstdint>
#include <memory>
#include <vector>

#include <dacrt/backend_tuning.hpp>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/trace_result.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"
#include "peers/embree_tracer.hpp"
#include "peers/rayquery_tracer.hpp"

namespace dacrt {

// Whether a trace is a new frame of its scene (the structure follows the triangles: rebuilt
// or refitted as its build mode says) or another pass of the frame just traced (the structure
// as that frame left it).
enum class PeerFrame { New, SamePass };

// One structure per peer option set (a run that interleaves configurations keeps each one's),
// all over the scene traced last (FrameGeometry::sceneId): a trace of another scene frees them.
// A frame with no sceneId gets a structure of its own, freed after it.
class PeerScenes {
public:
    PeerScenes();
    ~PeerScenes();

    // Embree: a scene's first trace builds (phase build); each new frame of a dynamic or refit
    // structure then updates it in place (a rebuild into the last one's memory, phase build, or
    // a refit, phase refit); a static one is built once per triangles' version and then only
    // traced.
    // onPlan sees the frame's plan first (embreePlan), which the result carries.
    TraceResult traceEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool,
                            const PlanHook& onPlan, PeerFrame frame);

    // Ray queries: a scene's first trace allocates (phase allocate) and builds; a dynamic or
    // refit structure is rebuilt or refitted by every trace, passes included (RayQueryScene
    // has no call that traces alone); a static one is built once per triangles' version.
    // onPlan sees the frame's plan first (stoppedAtPlan).
    TraceResult traceRayQuery(const FrameGeometry& geometry, RayQueryBuild build, gpu::Context& context,
                              gpu::PipelineCache& pipelines, const PlanHook& onPlan, PeerFrame frame);

    // Frees every kept structure: the next trace of a scene builds again, as its first did.
    void clear();

private:
    struct Kept;
    // traceEmbree over the structure kept for the geometry's scene.
    TraceResult traceKeptEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool,
                                PeerFrame frame);
    // The structure kept for these options over the geometry's scene, or null: the kept ones
    // of another scene are freed first.
    Kept* keptFor(const FrameGeometry& geometry, Backend backend, const EmbreeOptions& embree, RayQueryBuild build);
    Kept& keep(Backend backend, const EmbreeOptions& embree, RayQueryBuild build);

    std::uint64_t sceneId_ = 0;
    std::vector<std::unique_ptr<Kept>> kept_;
};

}  // namespace dacrt
