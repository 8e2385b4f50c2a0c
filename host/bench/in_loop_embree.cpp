#include "bench/in_loop_embree.hpp"

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "library/api_results.hpp"
#include "library/frame_passes.hpp"
#include "library/render_inputs.hpp"
#include "peers/embree_in_loop.hpp"

namespace dacrt {

double InLoopEmbree::build(const TraceScene& scene, const BenchConfig& config) {
    if (!config.raysInLoop || config.backend() != Backend::Embree)
        throw InternalError("only the embree rows with their rays made in the loop hold an InLoopEmbree");
    EmbreeOptions options = config.options.embree;
    options.threads = config.threads();  // as the Tracer gives Embree the trace's threads
    triangles_ = &sceneOf(scene).triangles;
    buildMode_ = options.build;
    scene_.reset();  // the old structure goes before the new one is made, as a renderer frees it
    scene_ = std::make_unique<EmbreeScene>(*triangles_, options);
    return scene_->buildMs();
}

void InLoopEmbree::release() {
    scene_.reset();
    pixels_.reset();
    hits_ = {};
    slots_ = {};
}

PhaseTimes InLoopEmbree::nextFrame() {
    if (!scene_) throw InternalError("an in-loop embree frame before its structure was built");
    PhaseTimes phases;
    if (buildMode_ != EmbreeBuild::Static)
        (buildMode_ == EmbreeBuild::Refit ? phases.refit : phases.build) = scene_->update();
    return phases;
}

PhaseTimes InLoopEmbree::tracePrimary(const Camera& camera, int width, int height, ThreadPool& pool) {
    if (!scene_) throw InternalError("an in-loop embree frame before its structure was built");
    PhaseTimes phases;
    const auto start = Clock::now();
    pixels_.emplace(camera, width, height);
    traceCameraInLoop(*scene_, *pixels_, pool, hits_);
    phases.trace = msSince(start);
    return phases;
}

PhaseTimes InLoopEmbree::occludeSecondary(const FramePass& pass, ThreadPool& pool, std::uint64_t& rays) {
    if (!pixels_) throw InternalError("an in-loop embree secondary pass before its primary pass");
    const auto start = Clock::now();
    rays = occludeSecondaryInLoop(*scene_, secondaryPassOf(pass), *pixels_, hits_, *triangles_, pool, slots_);
    PhaseTimes phases;
    phases.trace = msSince(start);
    return phases;
}

TraceOutput outputOf(const std::vector<Hit>& hits, const PhaseTimes& phases, unsigned threads, double ms) {
    TraceResult r;
    r.hits = hits;
    r.phases = phases;
    r.threads = threads;
    r.regions = 1;
    r.axis = -1;
    return traceOutputOf(r, {}, ms);
}

}  // namespace dacrt
