#pragma once
// One configuration's work for one frame of an animation, as a renderer of that animation pays
// it: dacrt's backends read the frame's triangles where the animation left them (bounds, then
// the trace; nothing kept from the frame before); a peer writes the new vertices into the array
// its structure reads in place, then rebuilds or refits the structure it keeps across frames.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_frame.hpp"
#include "bench/bench_rows.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

// A configuration's state across the frames: a peer's vertex array (shared with its structure,
// so it keeps its address while the triangle count stays) and its structure; the frame buffers.
struct AnimatedConfig {
    BenchConfig config;
    std::vector<Triangle> shared;
    PeerScenes peers;
    FrameBuffers buffers;
    double initialBuildMs = 0.0;  // the refit peers' structure built from the first frame, before the timing
};

// Makes the configuration's state for the first frame's triangles. A peer's structure is built
// here, untimed (a renderer builds it once when the animation starts; the frames then rebuild or
// refit it), and a ray query pipeline compiled.
std::unique_ptr<AnimatedConfig> startAnimatedConfig(const BenchConfig& config, const std::vector<Triangle>& first,
                                                    BackendDispatcher& dispatcher);

struct AnimatedWork {
    double prepareMs = 0.0;              // the rays (dacrt: and the triangle bounds, scene box, frame geometry)
    std::optional<double> buildMs;       // a peer's build or refit (a rebuild where the triangle count changed)
    double traceMs = 0.0;                // the rest: the trace (gpu: uploads, division, dispatches, readback)
    double workMs = 0.0;                 // prepare + build + trace
    double copyMs = 0.0;                 // a peer: the vertices copied into its array; not counted (below)
    bool rebuilt = false;                // a refit peer built its structure anew (the triangle count changed)
    std::vector<std::pair<std::string, double>> parts;
    std::vector<Hit> hits;
};

// The frame's work for the configuration. `topologyChanged`: the frame's triangle count differs
// from the previous frame's, which a refit cannot follow, so a refit peer rebuilds (in every
// repeat of the frame, as the one pass of a real animation would). The frame's triangles get a
// new version first: gpu uploads them as it would a new frame's. Pipeline compilation is not
// counted (a process's cost, as in the other suites).
AnimatedWork traceAnimatedFrame(AnimatedConfig& a, Scene& frame, const Camera& camera, int width, int height,
                                bool topologyChanged, BackendDispatcher& dispatcher);

}  // namespace dacrt
