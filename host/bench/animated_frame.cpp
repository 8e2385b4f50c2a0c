#include "bench/animated_frame.hpp"

#include "bench/bench_frame.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"

namespace dacrt {
namespace {

// A peer's structure over `a.shared` as it stands; returns the milliseconds the making took
// (Embree builds its BVH in it; a ray query scene only allocates, its first trace builds).
double makePeerStructure(AnimatedConfig& a, BackendDispatcher& dispatcher) {
    const auto start = Clock::now();
    a.peers = {};  // the old structure goes before the new one is made, as a renderer frees it
    if (a.config.backend() == Backend::Embree) {
        EmbreeOptions embree = a.config.request.embree;
        embree.threads = a.config.threads();
        a.peers.embree = std::make_unique<EmbreeScene>(a.shared, embree);
    } else {
        a.peers.rayQuery = std::make_unique<RayQueryScene>(*dispatcher.gpuContext(), *dispatcher.pipelines(), a.shared,
                                                           a.config.request.rayQueryBuild);
    }
    return msSince(start);
}

bool refits(const BenchConfig& c) {
    return c.backend() == Backend::Embree ? c.request.embree.build == EmbreeBuild::Refit
                                          : c.request.rayQueryBuild == RayQueryBuild::Refit;
}

AnimatedWork peerFrame(AnimatedConfig& a, const Scene& frame, const Camera& camera, int width, int height,
                       bool topologyChanged, BackendDispatcher& dispatcher) {
    AnimatedWork w;
    // A renderer that shares its vertex array with the structure writes the animation's
    // vertices straight into it; this bench's animation made a new scene, so the copy is the
    // bench's, timed and reported apart but not in the frame.
    const bool countChanged = frame.triangles.size() != a.shared.size();
    const Triangle* before = a.shared.data();
    auto start = Clock::now();
    a.shared.assign(frame.triangles.begin(), frame.triangles.end());
    w.copyMs = msSince(start);
    if (!countChanged && a.shared.data() != before)
        throw InternalError("bench: a peer's vertex array moved although its size stayed");
    // Dynamic peers rebuild every frame anyway; a new count needs new buffers for them too.
    const bool newStructure = countChanged || (topologyChanged && refits(a.config));
    w.rebuilt = newStructure && refits(a.config);

    start = Clock::now();
    ThreadPool& pool = dispatcher.pool(a.config.threads());
    primaryRays(camera, width, height, pool, a.buffers.rays);
    w.prepareMs = msSince(start);
    w.parts.emplace_back("rays", w.prepareMs);
    double makeMs = 0.0;
    if (newStructure) {
        makeMs = makePeerStructure(a, dispatcher);
        w.parts.emplace_back(a.peers.embree ? "build (new structure)" : "allocate (new structure)", makeMs);
    }
    TraceResult result;
    double buildMs = makeMs;
    const auto tracerStart = Clock::now();
    if (a.peers.embree) {
        if (!newStructure) {
            buildMs = a.peers.embree->update();
            w.parts.emplace_back(refits(a.config) ? "refit" : "build", buildMs);
        }
        result = a.peers.embree->trace(a.buffers.rays, pool);
    } else {
        result = a.peers.rayQuery->trace(a.buffers.rays);
        buildMs += result.phases.structureMs();
    }
    const double tracerMs = msSince(tracerStart);
    // Pipeline compilation within a trace is a cost of the process, not of the frame.
    const double compiled = result.phases.compileMs();
    w.buildMs = buildMs;
    // Embree's update is timed inside the tracer's span; the ray queries' build runs in the
    // same command buffer as their trace (its GPU timestamps), the making of a new structure
    // before it.
    w.traceMs = tracerMs - compiled - (buildMs - makeMs);
    w.workMs = w.prepareMs + buildMs + w.traceMs;
    for (const auto& p : result.phases.listed()) w.parts.push_back(p);
    addGpuTimestamps(result, w.parts);
    w.parts.emplace_back("not counted: vertex copy", w.copyMs);
    w.hits = std::move(result.hits);
    return w;
}

AnimatedWork dacrtFrame(AnimatedConfig& a, Scene& frame, const Camera& camera, int width, int height,
                        BackendDispatcher& dispatcher) {
    AnimatedWork w;
    touchTriangles(frame);  // a new frame's triangles: gpu may not keep the last upload
    const auto start = Clock::now();
    ThreadPool& pool = dispatcher.pool(a.config.threads());
    primaryRays(camera, width, height, pool, a.buffers.rays);
    Box box;
    triangleBoundsInParallel(frame.triangles, pool, a.buffers.bounds, box);
    FrameGeometry geometry = frameGeometry(frame.triangles, a.buffers.bounds, a.buffers.rays, box, std::uint32_t(width));
    geometry.frustum = viewFrustum(camera, width, height);
    geometry.trianglesVersion = frame.trianglesVersion;
    w.prepareMs = msSince(start);
    w.parts.emplace_back("rays and bounds", w.prepareMs);
    const auto traceStart = Clock::now();
    TraceResult result = dispatcher.trace(geometry, a.config.request);
    w.traceMs = msSince(traceStart) - result.phases.compileMs();
    w.workMs = w.prepareMs + w.traceMs;
    for (const auto& p : result.phases.listed()) w.parts.push_back(p);
    addGpuTimestamps(result, w.parts);
    w.hits = std::move(result.hits);
    return w;
}

}  // namespace

std::unique_ptr<AnimatedConfig> startAnimatedConfig(const BenchConfig& config, const std::vector<Triangle>& first,
                                                    BackendDispatcher& dispatcher) {
    auto a = std::make_unique<AnimatedConfig>();
    a->config = config;
    if (!isPeer(config.backend())) return a;
    a->shared = first;
    a->initialBuildMs = makePeerStructure(*a, dispatcher);
    if (a->peers.rayQuery) {
        // The first trace builds the structure (and compiles the pipeline): outside the frames.
        const auto start = Clock::now();
        const TraceResult built = a->peers.rayQuery->trace({makeRay(glm::vec3(0.0f), glm::dvec3(0.0, 0.0, -1.0))});
        a->initialBuildMs += msSince(start) - built.phases.compileMs();
    }
    return a;
}

AnimatedWork traceAnimatedFrame(AnimatedConfig& a, Scene& frame, const Camera& camera, int width, int height,
                                bool topologyChanged, BackendDispatcher& dispatcher) {
    return isPeer(a.config.backend()) ? peerFrame(a, frame, camera, width, height, topologyChanged, dispatcher)
                                      : dacrtFrame(a, frame, camera, width, height, dispatcher);
}

}  // namespace dacrt
