#pragma once
// Any-hit rays (shadow and occlusion) traced as one DACRT whose upper levels are divided once,
// on every worker together, and whose subtrees are then traced side by side.
//
// A pass cut into ray groups, one a worker, divides every triangle again in each group: the
// Dragon's occlusion rays cover the whole model from either half of the image, so each of two
// groups filtered nearly all 871k triangles at every level (docs/benchmarks.md, "Subtrees
// side by side"). Here the top of the recursion is split by sequential DACRT's rules (the
// longest axis at the spatial median, its leaf and stall rules, which count here every ray a
// node is given, those a sibling would have ended included; the cells unshrunk: the tight node
// boxes start in the subtrees), each split's rays and triangles
// filtered in chunks on the pool, until there are subtrees enough to share out; each subtree is
// then a sequential DACRT on one worker, from its depth down.
//
// Two subtrees may share a ray, which sequential DACRT would not send into the second once the
// first had ended it: here both trace it, each into its worker's own hits, and the subtree that
// sequential DACRT visits first gives the ray its hit. The visibility bit is exact either way
// (every subtree a ray crosses tests it against every triangle there where a hit could lie), and
// the reported hit is one of the ray's own in its segment, the same on every run.
#include <cstdint>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// Subtrees the upper levels are divided into, per worker: enough for the dynamic hand-out to
// even out their unequal costs, few enough that rays crossing several are traced again seldom
// (measured: docs/benchmarks.md, "Subtrees side by side").
constexpr unsigned kSubtreesPerWorker = 4;

// Whether traceSubtrees takes a frame of `rays` rays over `triangles` traced triangles: any-hit
// rays, fewer than the triangles (where rays outnumber them, the groups' own filtering of every
// triangle costs less than the rays traced again in a second subtree: the room's occlusion pass
// took 1.3-1.5x as long as subtrees, docs/benchmarks.md), on the SIMD kernels of the default
// options, whose split reads no triangle order (the spatial median under the leaf limits), on
// more than one worker.
bool tracesAsSubtrees(std::uint64_t rays, std::uint64_t triangles, HitQuery query, const DacrtOptions& options,
                      unsigned workers);
bool tracesAsSubtrees(const FrameGeometry& geometry, const DacrtOptions& options, unsigned workers);

// The frame's rays traced as described above, on every worker of the pool. Only where
// tracesAsSubtrees (else InternalError).
TraceResult traceSubtrees(const FrameGeometry& geometry, const DacrtOptions& options, ThreadPool& pool,
                          const PlanHook& onPlan = {});

}  // namespace dacrt
