#pragma once
// The bench's default embree rows: Embree as a renderer on it runs (peers/embree_in_loop.hpp),
// held here beside the Tracer, as such a renderer holds it: its scene built when a scene
// appears, then each frame rebuilt (dynamic), refitted (refit) or kept (static), and every ray
// made in the tracing loop. The rows with `stored rays` in their name run Embree through the
// Tracer instead, on rays the bench made and stored first (BenchConfig::raysInLoop false).
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <dacrt/frame.hpp>
#include <dacrt/results.hpp>
#include <dacrt/scene.hpp>

#include "bench/bench_rows.hpp"
#include "core/camera.hpp"
#include "core/thread_pool.hpp"
#include "cpu/phase_times.hpp"
#include "peers/embree_tracer.hpp"

namespace dacrt {

class InLoopEmbree {
public:
    // The structure over the scene's triangles, built as a renderer builds it when a scene
    // appears (the scene must outlive it, its triangles keeping their array). Returns the
    // milliseconds it took.
    double build(const TraceScene& scene, const BenchConfig& config);

    // A new frame of the scene (its vertices may have moved): the structure rebuilt, refitted
    // or kept as the build mode says. Returns its phase (build, refit, or none).
    PhaseTimes nextFrame();

    // The frame's primary pass: the camera's rays made and traced in the loop into hits().
    // Returns its phase (trace).
    PhaseTimes tracePrimary(const Camera& camera, int width, int height, ThreadPool& pool);

    // A secondary pass of the frame tracePrimary traced last, from its hits, into slots().
    // Returns its phases (trace) and the rays it made.
    PhaseTimes occludeSecondary(const FramePass& pass, ThreadPool& pool, std::uint64_t& rays);

    // Frees the structure and the frame buffers: build makes them again.
    void release();

    const std::vector<Hit>& hits() const { return hits_; }
    const std::vector<Hit>& slots() const { return slots_; }

private:
    std::unique_ptr<EmbreeScene> scene_;
    const std::vector<Triangle>* triangles_ = nullptr;
    EmbreeBuild buildMode_ = EmbreeBuild::Dynamic;
    std::optional<PixelRays> pixels_;  // the last primary pass's camera
    // The frame buffers, their memory kept from frame to frame.
    std::vector<Hit> hits_, slots_;
};

// An in-loop pass as the public API reports a trace (the answers and phases), for the checks
// and the parts, made after the pass's time was taken.
TraceOutput outputOf(const std::vector<Hit>& hits, const PhaseTimes& phases, unsigned threads, double ms);

}  // namespace dacrt
