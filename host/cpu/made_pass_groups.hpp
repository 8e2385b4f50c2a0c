#pragma once
// A secondary pass made and traced in groups side by side, as a renderer on a BVH makes its
// rays in its tracing loop: each worker makes the rays of a run of primary pixels into arrays of
// its own and traces them as a sequential DACRT, writing each answer to its slot. An occlusion
// pass's worker traces its group as soon as it is made; a shadow pass's groups are all made
// first, each surveying its rays for the pass cull's back-face tests (RaySurvey), then culled
// once from the surveys and traced. No array of the pass's rays is made, copied into groups or
// scanned (for the plan or the cull), and no array of its hits is gathered before the slots
// are filled (docs/benchmarks.md, "Occlusion rays made where they are traced, a pass's own
// triangle limit", and "Shadow rays made where they are traced").
#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/options.hpp"
#include "cpu/pass_cull.hpp"
#include "cpu/secondary_rays.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// What a worker keeps from pass to pass: its group's rays and their slots.
struct MadeGroupBuffers {
    std::vector<Ray> rays;
    std::vector<std::uint32_t> slots;
};

// Whether the cpu backend makes and traces a pass of at most raysAtMost rays over `triangles`
// triangles so: an occlusion or shadow pass in batches (RayGrouping::Batches), on more than one
// worker without regions asked for, which the pass cull's grid would not survey and which is
// not traced as subtrees (cpuTracesAsSubtrees: fewer rays than triangles), both judged from the
// most rays it can make. Elsewhere the pass's rays are made first, then traced
// (BackendDispatcher::traceSecondary); so is a shadow pass whose rays, once made, are few
// enough for either (MadePass::unmade).
bool tracesMadeSideBySide(const SecondaryPass& pass, std::uint64_t raysAtMost, std::size_t triangles,
                          const TraceOptions& options, unsigned workers);

// Where the groups of a pass's primary rays start: as many groups as rayBatches gives for the
// pass's rays at most, in batches of passBatchRays(triangles), each group the primary rays up
// to its batch's end (found in counts' chunks, then ray by ray in primaryHits). first[k] is
// group k's first primary ray (first.back(): every primary ray), raysBefore[k] the rays at
// most the groups before it make. Every group but the last makes rays.
struct MadeGroups {
    std::vector<std::size_t> first;
    std::vector<std::size_t> raysBefore;
    std::size_t count() const { return first.size() - 1; }
    std::size_t raysAtMost(std::size_t k) const { return raysBefore[k + 1] - raysBefore[k]; }
    std::size_t largestAtMost() const {
        std::size_t largest = 0;
        for (std::size_t k = 0; k < count(); ++k) largest = std::max(largest, raysAtMost(k));
        return largest;
    }
};
MadeGroups madeGroups(const PassRayCounts& counts, const std::vector<Hit>& primaryHits, std::uint32_t raysPerHit,
                      std::size_t triangles, unsigned workers);

struct MadePass {
    TraceResult result;  // hits per slot (hitsPerSlot's), the groups' counters summed
    std::uint64_t rays = 0;
    // A shadow pass whose rays, once made, are few enough for the cull's grid or for subtrees:
    // its rays in slot order (makeSecondaryRays'), untraced, and how long making them took.
    std::optional<SecondaryRays> unmade;
    double makeMs = 0.0;
};

// The pass made and traced as tracesMadeSideBySide says, on the pool's workers (buffers: one
// a worker for an occlusion pass, one a group for a shadow pass; kept for the next pass; cull:
// the shadow pass's, its buffers reused). onPlan sees the plan of what is made (the hits per
// slot, and each worker's group or every group's rays), from the counts before any ray is made,
// then the plan of the trace (the cull's lines, each worker's sequential DACRT of the largest
// group): an occlusion pass's from the counts too, a shadow pass's after its cull. The hits are
// cpu-seq's visibility, bit for bit (the rays are makeSecondaryRays', traced for any hit, over
// the triangles the cull of their array would keep: cullFromSurvey).
MadePass traceMadeSideBySide(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                             const SecondaryPass& pass, const PassRayCounts& counts, const TraceOptions& options,
                             ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, PassCull& cull,
                             const PlanHook& onPlan);

}  // namespace dacrt
