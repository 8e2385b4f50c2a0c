#pragma once
// A camera frame with its secondary passes (Tracer::traceFrame): after the primary rays, a
// shadow pass towards each light and an ambient-occlusion pass, their rays made from the
// primary hits by the backend that traced them (gpu: on the device, where the hits lie, but
// on the host for a pass whose triangles the pass cull may thin, as on the other backends).
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <dacrt/options.hpp>
#include <dacrt/results.hpp>

namespace dacrt {

enum class LightKind { Point, Spot, Directional };

// A light as its shadow pass traces it, in float32.
struct PassLight {
    LightKind kind = LightKind::Point;
    std::array<float, 3> position{};   // point, spot
    std::array<float, 3> direction{};  // spot, directional: where the light travels, unit
    float range = 0.0f;                // 0: unlimited
    float cosOuterSquared = 0.0f;      // spot: cos^2 of the outer cone angle (at most pi/2)
};

enum class PassKind { Shadow, Occlusion };

struct FramePass {
    std::string name;                // as reports name it: "shadow: key light", "occlusion"
    PassKind kind = PassKind::Shadow;
    PassLight light;                 // shadow: one ray per primary hit towards it
    std::uint32_t raysPerHit = 1;    // occlusion: rays per primary hit, over the hemisphere
    float occlusionDistance = 0.0f;  // occlusion: the rays' length
    std::uint32_t sampleSeed = 0;    // occlusion: picks the sample sequence
};

struct PassOutput {
    FramePass pass;
    // hits: one per slot (primary ray x raysPerHit), kNotTracedPrimitive where no ray was made;
    // any-hit answers, as occluded()'s.
    TraceOutput output;
    std::uint64_t rays = 0;  // rays made
    double ms = 0.0;         // making and tracing them
    // kTracedAlone where the pass was traced on its own; else (DacrtOptions::passTracing,
    // together) the index in FrameOutput::passes of the last pass it was traced with, whose
    // output carries the shared trace's time, plan and counters (this pass's own index where it
    // is that pass); the others carry their hits and rays only.
    static constexpr std::size_t kTracedAlone = ~std::size_t(0);
    std::size_t tracedIn = kTracedAlone;
};

struct FrameOutput {
    TraceOutput primary;
    std::vector<PassOutput> passes;  // in the order given
    bool stoppedAtPlan = false;      // a plan callback said stop: nothing was traced after it
};

// Called with the plan of the primary pass, then with each plan of the secondary passes (one or
// more each), before what it plans is traced: false stops the frame there. It may throw (a plan too large for the machine).
using PlanCallback = std::function<bool(const FramePlan&)>;
// Called with the fraction done, by the backends that report progress (brute).
using ProgressCallback = std::function<void(double)>;

// What a pass will allocate at most, from the counts alone (the primary hits decide how many
// rays it makes).
FramePlan passPlanBound(const FramePass& pass, std::uint64_t primaryRays, Backend backend);

// The least memory a camera frame of `primaryRays` rays with these passes holds at once,
// whatever the backend and its division into sub-scenes, from the counts alone (no ray made):
// the rays and their hits (the caller holds the rays; every backend's plan of the primary pass
// counts both) and each pass's hit per slot (primary ray x raysPerHit; made whatever the
// primary hits, and kept until the frame is shaded). The frame's detailed plans add their
// working buffers to it: a frame whose bound exceeds the memory can be refused before its rays
// are made. Throws InputError where a pass would hold more slots than it can (as traceFrame).
FramePlan frameMemoryBound(std::uint64_t primaryRays, const std::vector<FramePass>& passes);

}  // namespace dacrt
