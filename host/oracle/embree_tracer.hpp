#pragma once
// Embree 3 as a peer backend and an independent oracle: a BVH over the same float32
// triangles, traced with the same rays. Its answers are Embree's own (not watertight by
// construction, ties between coincident triangles unspecified), so dacrt's benchmark
// measures its error against the float64 reference like any other backend.
#include <memory>
#include <vector>

#include "core/thread_pool.hpp"
#include "dacrt/frame_geometry.hpp"
#include "dacrt/trace_result.hpp"

namespace dacrt {

struct EmbreeOptions {
    // RTC_SCENE_FLAG_ROBUST: no leaks through shared edges, 3-7% slower. On by default, unlike
    // Embree itself: without it Embree leaks real pixels on the Bunny's orbit (docs/benchmarks.md).
    bool robust = true;
    unsigned threads = 0; // threads of Embree's BVH build; 0: every core
};

// One Embree device and one committed scene over the given triangles (built in the
// constructor: that is the per-frame cost of a dynamic scene). Throws std::runtime_error
// with Embree's error text on failure.
class EmbreeScene {
public:
    EmbreeScene(const std::vector<Triangle>& triangles, const EmbreeOptions& options);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    double buildMs() const { return buildMs_; }

    // Closest hit of every ray (t > ray.tmin), traced on the pool's threads. phaseMs holds
    // {"trace", ms}; counters stay zero (Embree does not report them).
    TraceResult trace(const std::vector<Ray>& rays, ThreadPool& pool) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    double buildMs_ = 0.0;
};

// A dynamic-scene frame: build, then trace. phaseMs holds {"build", ms} and {"trace", ms}.
TraceResult traceEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool);

}  // namespace dacrt
