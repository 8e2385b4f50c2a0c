#pragma once
// One configuration's work for one frame of an animation, as a renderer of that animation pays
// it, through the run's Tracer. The frames' posed triangles go into one TraceScene, written into
// its array in place (library/render_inputs.hpp replaceScene): dacrt's backends read them where
// the animation left them (bounds, then the trace; nothing kept from the frame before), and a
// peer rebuilds or refits the structure it keeps over that array.
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_frame.hpp"
#include "bench/bench_rows.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

// A configuration's state across the frames.
struct AnimatedConfig {
    BenchConfig config;
    std::vector<Ray> rays;        // the camera rays' memory, kept from frame to frame
    double initialBuildMs = 0.0;  // a peer's structure built from the first frame, before the timing
    InLoopEmbree embree;          // embree with its rays made in the loop: its structure and frame buffer
};

// The configuration's state for the first frame's scene. A peer's structure is built here,
// untimed (a renderer builds it once when the animation starts; the frames then rebuild or
// refit it), and a ray query pipeline compiled.
AnimatedConfig startAnimatedConfig(const BenchConfig& config, const TraceScene& first, BenchRun& run);

struct AnimatedWork {
    double prepareMs = 0.0;              // the camera rays
    std::optional<double> buildMs;       // a peer's build or refit (a new structure's where the scene is new)
    double traceMs = 0.0;                // the rest: the trace (dacrt: the triangles' bounds, then the backend)
    double workMs = 0.0;                 // prepare + build + trace
    double copyMs = 0.0;                 // a peer: the frame's vertices copied into the scene; not counted (below)
    bool rebuilt = false;                // a refit peer built its structure anew (the triangle count changed)
    std::vector<std::pair<std::string, double>> parts;
    std::vector<Hit> hits;
};

// The frame's work for the configuration on `scene`, the frame's. `newScene`: the scene was made
// anew for the frame (its triangle count differs from the previous frame's, which a refit
// cannot follow), so a peer builds a new structure (in every repeat of the frame, as the one
// pass of a real animation would). copyMs: the frame's vertices written into the scene (a
// renderer that shares its vertex array with the structure writes the animation's vertices
// straight into it; this bench's animation made a new scene, so the copy is the bench's,
// reported for the peers but not in the frame). Pipeline compilation is not counted (a
// process's cost, as in the other suites).
AnimatedWork traceAnimatedFrame(AnimatedConfig& a, const TraceScene& scene, const Camera& camera, int width, int height,
                                bool newScene, double copyMs, BenchRun& run);

}  // namespace dacrt
