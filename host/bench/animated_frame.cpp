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

}  // namespace

AnimatedConfig startAnimatedConfig(const BenchConfig& config, const TraceScene& first, BenchRun& run) {
    return AnimatedConfig{config, {}, prepareStructure(run, config, first)};
}

AnimatedWork traceAnimatedFrame(AnimatedConfig& a, const TraceScene& scene, const Camera& camera, int width, int height,
                                bool newScene, double copyMs, BenchRun& run) {
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
    if (peer) {
        if (newScene) nameNewStructure(a.config, w.parts);
        w.rebuilt = newScene && refits(a.config);
        w.copyMs = copyMs;
        w.parts.emplace_back("not counted: vertex copy", copyMs);
    }
    w.hits = hitsOf(out.hits);
    return w;
}

}  // namespace dacrt
