#pragma once
// A frame's secondary passes traced after the primary pass by the same backend, and their
// public description (include/dacrt/frame.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include <dacrt/frame.hpp>

#include "core/lights.hpp"
#include "library/backend_dispatcher.hpp"
#include "library/pass_options.hpp"
#include "cpu/secondary_rays.hpp"

namespace dacrt {

// One shadow pass per light, then the occlusion pass (with --ao), in the order their results
// are shaded. seed picks the occlusion sample sequence (an antialiasing sample's own).
std::vector<SecondaryPass> secondaryPasses(const std::vector<Light>& lights, const PassOptions& options,
                                           const Box& sceneBox, std::uint32_t seed);

struct TracedPass {
    SecondaryPass pass;
    TraceResult result;        // hits: one per slot
    std::uint64_t rays = 0;    // rays made
    double ms = 0.0;           // making and tracing them
    std::size_t tracedIn = PassOutput::kTracedAlone;  // as PassOutput's
};

// Whether the cpu backends trace these passes together (PassTracing; Auto: where they make
// fewer rays, raysPerHit for each primary hit that sends rays, than there are triangles).
bool passesTracedTogether(const std::vector<SecondaryPass>& passes, const std::vector<Hit>& primaryHits,
                          std::size_t triangles, const BackendRequest& request);

// Each pass in turn on the backend that traced `primary` (the dispatcher's last frame), or all
// of them in one trace where passesTracedTogether.
std::vector<TracedPass> traceSecondaryPasses(const std::vector<SecondaryPass>& passes, const FrameGeometry& primary,
                                             const std::vector<Hit>& primaryHits, BackendDispatcher& backends,
                                             const BackendRequest& request, const PlanHook& onPlan);

// The passes as the public API describes them (Tracer::traceFrame), and back.
SecondaryPass secondaryPassOf(const FramePass& pass);
FramePass framePassOf(const SecondaryPass& pass);

// What a pass will allocate at most, from the counts alone (--plan: the primary hits that
// decide how many rays each pass makes are not traced then).
MemoryPlan secondaryPassBound(const SecondaryPass& pass, std::uint64_t primaryRays, Backend backend);

}  // namespace dacrt
