#pragma once
// Embree 3 as a peer backend and an independent oracle: a BVH over the same float32
// triangles, traced with the same rays. Its answers are Embree's own (not watertight by
// construction, ties between coincident triangles unspecified), so dacrt's benchmark
// measures its error against the float64 reference like any other backend.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <dacrt/backend_tuning.hpp>

#include "cpu/options.hpp"  // EmbreeBuild's names
#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/trace_result.hpp"

struct RTCSceneTy;  // Embree's scene (embree3/rtcore_scene.h: RTCScene is a pointer to it)

namespace dacrt {

// One Embree device (per thread count, for the whole process) and one committed scene over
// the given triangles, whose vertices Embree reads in place (a shared buffer: the array must
// outlive the scene and keep its address). Throws std::runtime_error with Embree's error text
// on failure.
class EmbreeScene {
public:
    EmbreeScene(const std::vector<Triangle>& triangles, const EmbreeOptions& options);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    double buildMs() const { return buildMs_; }

    // What Embree allocated for this structure, from the device's memory monitor: what it
    // holds after its build, and the most it held during the build (temporaries included).
    // Counted device-wide, so exact only where no other structure builds on the device at once.
    struct Memory {
        std::uint64_t held = 0, buildPeak = 0;
    };
    Memory memory() const { return memory_; }

    // After the triangles' vertices moved (same count): refit (Refit) or rebuild (otherwise).
    // Returns the milliseconds it took.
    double update();

    // Every ray's answer within its segment (ray.tmin < t <= ray.tmax), traced on the pool's
    // threads with flush-to-zero and denormals-are-zero on (restored afterwards: the same
    // threads run dacrt). Closest: the closest hit (rtcIntersect), missHit(ray) for a miss.
    // Any: occlusion (rtcOccluded), which stops at any hit and reports none of it: an occluded
    // ray gets Hit{ray.tmin, kUnnamedHitPrim, 0, 0}, t being only a bound the hit lies beyond,
    // an unoccluded one missHit(ray). imageWidth: the rays' image width (0: not an image), for
    // a scene that traces both a camera's rays and secondary rays; unset: the options'.
    // phases holds trace; counters stay zero (Embree does not report them).
    TraceResult trace(const std::vector<Ray>& rays, ThreadPool& pool, HitQuery query = HitQuery::Closest,
                      std::optional<std::uint32_t> imageWidth = std::nullopt) const;

    // For the tracers that make their rays in the loop (peers/embree_in_loop.hpp): the
    // committed scene, and the text of the last failed Embree call on the calling thread, named
    // `call` (empty: none failed).
    RTCSceneTy* handle() const;
    std::string pendingError(const char* call) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    double buildMs_ = 0.0;
    Memory memory_;
};

// A dynamic-scene frame: build, then trace the frame's rays for its query, in tiles where the
// frame says its rays are an image. phases holds build and trace.
TraceResult traceEmbree(const FrameGeometry& geometry, const EmbreeOptions& options, ThreadPool& pool);

// The frame's memory as Embree holds it: its structure and index buffer by their bound from
// the triangle count (peers/embree_memory.hpp), the triangles it reads in place, and the hits;
// its work, the rays.
MemoryPlan embreePlan(const FrameGeometry& geometry);

}  // namespace dacrt
