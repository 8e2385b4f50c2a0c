#include "library/peer_scenes.hpp"

#include <optional>

#include "core/timing.hpp"

namespace dacrt {

struct PeerScenes::Kept {
    Backend backend = Backend::Embree;
    EmbreeOptions embree;        // embree: the options it was built with (the image width aside)
    RayQueryBuild rayQueryBuild = RayQueryBuild::Dynamic;
    std::size_t triangles = 0;   // the count it was built over
    std::uint64_t version = 0;   // the triangles' version it was last built or updated for
    std::unique_ptr<EmbreeScene> embreeScene;
    std::unique_ptr<RayQueryScene> rayQueryScene;

    // A static structure cannot follow moved vertices: it is built again for another version
    // (0: unknown, so always).
    bool staleFor(const FrameGeometry& g) const { return version == 0 || version != g.trianglesVersion; }
};

PeerScenes::PeerScenes() = default;
PeerScenes::~PeerScenes() = default;

void PeerScenes::clear() {
    kept_.clear();
    sceneId_ = 0;
}

PeerScenes::Kept* PeerScenes::keptFor(const FrameGeometry& g, Backend backend, const EmbreeOptions& embree,
                                      RayQueryBuild build) {
    if (g.sceneId != sceneId_) {
        kept_.clear();  // another scene: what was kept over the last one is of no more use
        sceneId_ = g.sceneId;
    }
    for (const std::unique_ptr<Kept>& k : kept_) {
        const bool same = backend == Backend::Embree ? k->embree == embree : k->rayQueryBuild == build;
        if (k->backend == backend && same) return k->triangles == g.triangles->size() ? k.get() : nullptr;
    }
    return nullptr;
}

PeerScenes::Kept& PeerScenes::keep(Backend backend, const EmbreeOptions& embree, RayQueryBuild build) {
    for (std::unique_ptr<Kept>& k : kept_) {
        const bool same = backend == Backend::Embree ? k->embree == embree : k->rayQueryBuild == build;
        if (k->backend == backend && same) return *k;  // a count that changed: made anew in place
    }
    kept_.push_back(std::make_unique<Kept>());
    Kept& k = *kept_.back();
    k.backend = backend;
    k.embree = embree;
    k.rayQueryBuild = build;
    return k;
}

TraceResult PeerScenes::traceEmbree(const FrameGeometry& g, const EmbreeOptions& options, ThreadPool& pool,
                                    const PlanHook& onPlan, PeerFrame frame) {
    TraceResult result;
    result.memory = embreePlan(g);
    if (onPlan && !onPlan(result.memory)) return result;  // stopped at the plan: no hits
    const MemoryPlan plan = std::move(result.memory);
    result = g.sceneId == 0 ? dacrt::traceEmbree(g, options, pool) : traceKeptEmbree(g, options, pool, frame);
    result.memory = plan;
    return result;
}

TraceResult PeerScenes::traceKeptEmbree(const FrameGeometry& g, const EmbreeOptions& options, ThreadPool& pool,
                                        PeerFrame frame) {
    EmbreeOptions key = options;
    key.imageWidth = 0;  // chosen per trace: the frame names its own
    Kept* k = keptFor(g, Backend::Embree, key, {});
    const bool newFrame = frame == PeerFrame::New;
    std::optional<double> build, refit;
    if (!k || !k->embreeScene || (newFrame && options.build == EmbreeBuild::Static && k->staleFor(g))) {
        k = &keep(Backend::Embree, key, {});
        k->embreeScene.reset();  // the old structure goes before the new one is made, as a renderer frees it
        k->embreeScene = std::make_unique<EmbreeScene>(*g.triangles, options);
        build = k->embreeScene->buildMs();
    } else if (newFrame && options.build != EmbreeBuild::Static) {
        const double ms = k->embreeScene->update();
        (options.build == EmbreeBuild::Refit ? refit : build) = ms;
    }
    k->triangles = g.triangles->size();
    k->version = g.trianglesVersion;
    TraceResult result = k->embreeScene->trace(*g.rays, pool, g.query, g.imageWidth);
    result.phases.build = build;
    result.phases.refit = refit;
    return result;
}

TraceResult PeerScenes::traceRayQuery(const FrameGeometry& g, RayQueryBuild build, gpu::Context& context,
                                      gpu::PipelineCache& pipelines, const PlanHook& onPlan, PeerFrame frame) {
    if (g.sceneId == 0) return dacrt::traceRayQuery(g, context, pipelines, onPlan);
    if (std::optional<TraceResult> planned = stoppedAtPlan(g, onPlan)) return *planned;
    Kept* k = keptFor(g, Backend::RayQuery, {}, build);
    std::optional<double> allocate;
    if (!k || !k->rayQueryScene || (frame == PeerFrame::New && build == RayQueryBuild::Static && k->staleFor(g))) {
        k = &keep(Backend::RayQuery, {}, build);
        k->rayQueryScene.reset();
        const auto start = Clock::now();
        k->rayQueryScene = std::make_unique<RayQueryScene>(context, pipelines, *g.triangles, build);
        allocate = msSince(start);
    }
    k->triangles = g.triangles->size();
    k->version = g.trianglesVersion;
    TraceResult result = k->rayQueryScene->trace(*g.rays, g.query);
    if (allocate) result.phases.allocate = allocate;
    return result;
}

}  // namespace dacrt
