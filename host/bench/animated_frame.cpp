#include "bench/animated_frame.hpp"

#include "core/timing.hpp"

namespace dacrt {
namespace {

bool refits(const BenchConfig& c) {
    return c.backend() == Backend::Embree ? c.options.embree.build == EmbreeBuild::Refit
                                          : c.options.rayQueryBuild == RayQueryBuild::Refit;
}

// A peer's structure made for a new scene is named apart from the per-frame build or refit:
// Embree's build, the ray queries' allocation (their build follows in the trace's command
// buffer, as every frame's).
void nameNewStructure(const BenchConfig& c, std::vector<std::pair<std::string, double>>& parts) {
    const std::string made = c.backend() == Backend::Embree ? "build" : "allocate";
    for (auto& [name, ms] : parts)
        if (name == made) name += " (new structure)";
}

// A peer's frame after its work: a new structure's build named apart, the vertex copy
// reported, the hits kept.
void finishPeerFrame(const AnimatedConfig& a, bool newScene, double copyMs, const TraceOutput& out, AnimatedWork& w) {
    if (newScene) nameNewStructure(a.config, w.parts);
    w.rebuilt = newScene && refits(a.config);
    w.copyMs = copyMs;
    w.parts.emplace_back("not counted: vertex copy", copyMs);
    w.hits = hitsOf(out.hits);
}

// The frame of embree with its rays made in the loop: a new structure for a new scene (as the
// Tracer builds one when it meets another scene), else the structure rebuilt or refitted; then
// the camera's rays made and traced together.
AnimatedWork traceInLoop(AnimatedConfig& a, const TraceScene& scene, const Camera& camera, int width, int height,
                         bool newScene, double copyMs, BenchRun& run) {
    ThreadPool& pool = run.pools.of(a.config.threads());
    AnimatedWork w;
    const auto start = Clock::now();
    PhaseTimes phases;
    if (newScene) phases.build = a.embree.build(scene, a.config);
    else phases = a.embree.nextFrame();
    phases.add(a.embree.tracePrimary(camera, width, height, pool));
    w.workMs = msSince(start);
    w.buildMs = phases.structureMs();
    w.traceMs = w.workMs - *w.buildMs;
    const TraceOutput out = outputOf(a.embree.hits(), phases, pool.size(), w.workMs);
    addTraceParts(out, w.parts);
    finishPeerFrame(a, newScene, copyMs, out, w);
    return w;
}

}  // namespace

AnimatedConfig startAnimatedConfig(const BenchConfig& config, const TraceScene& first, BenchRun& run) {
    AnimatedConfig a{config, {}, 0.0, {}};
    a.initialBuildMs = prepareStructure(run, config, first, a.embree);
    return a;
}

AnimatedWork traceAnimatedFrame(AnimatedConfig& a, const TraceScene& scene, const Camera& camera, int width, int height,
                                bool newScene, double copyMs, BenchRun& run) {
    if (a.config.raysInLoop) return traceInLoop(a, scene, camera, width, height, newScene, copyMs, run);
    useConfig(run.tracer, a.config);
    AnimatedWork w;
    const bool peer = isPeer(a.config.backend());
    const auto start = Clock::now();
    RayBatch rays = makeCameraRays(camera, width, height, run.pools.of(a.config.threads()), a.rays);
    w.prepareMs = msSince(start);
    w.parts.emplace_back("rays", w.prepareMs);
    const auto tracerStart = Clock::now();
    const TraceOutput out = run.tracer.trace(scene, rays);
    const double tracerMs = msSince(tracerStart);
    a.rays = releaseRays(std::move(rays));
    // Pipeline compilation within a trace is a cost of the process, not of the frame. A peer's
    // build or refit is apart from its trace: Embree's ran within the tracer's span, the ray
    // queries' on the device in the trace's command buffer (its GPU timestamps), a new
    // structure's allocation before it.
    const double compiled = out.timings.pipelineCompileMs;
    if (peer) w.buildMs = out.timings.buildMs + out.timings.allocateMs;
    w.traceMs = tracerMs - compiled - w.buildMs.value_or(0.0);
    w.workMs = w.prepareMs + w.buildMs.value_or(0.0) + w.traceMs;
    addTraceParts(out, w.parts);
    if (peer) finishPeerFrame(a, newScene, copyMs, out, w);
    else w.hits = hitsOf(out.hits);
    return w;
}

}  // namespace dacrt
