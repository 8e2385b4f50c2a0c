#pragma once
// The triangle skips of a frame, decided before anything is traced: triangles that no ray of
// the frame can hit, dropped so that no backend divides, filters or tests them. Each is exact
// by construction (docs/correctness.md, "Skips"): a triangle is dropped only where the
// intersection test provably never reports it for these rays.
#include <cstdint>
#include <utility>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"

namespace dacrt {

struct TriangleSkips {
    bool applied = false;                // false: nothing dropped, every triangle traced
    std::vector<std::uint32_t> traced;   // the kept ids, ascending (when applied)
    Box tracedBox;                       // their exact bounds (when applied)
    std::uint64_t singleSided = 0;       // triangles whose back face is culled (counted when applied)
    std::uint64_t backFacing = 0;        // dropped: single-sided, facing away from the shared origin
    std::uint64_t outsideFrustum = 0;    // dropped: outside the view frustum (and not back-facing)
    bool frustumTested = false;          // false where the scene box lies inside the view
};

// The facing tests' bound (docs/correctness.md, "Skips"): side / R^2 > kFacingPerEdge L +
// kFacingPerReach R, with L the longest edge and R the reach, u = 2^-24 float32's unit roundoff.
constexpr double kFacingPerEdge = 480.0 * 0x1p-24, kFacingPerReach = 200.0 * 0x1p-24 * 0x1p-24;

// Whether a single-sided triangle faces away from `origin` by a margin that no rounding of the
// watertight test (or Moller-Trumbore's, or float64's) can overcome: every ray from origin
// then meets its back, and the face rule rejects it.
bool facesAwayFrom(const Triangle& triangle, const glm::dvec3& origin);
// Whether a single-sided triangle faces away from `direction` by the same margin, for rays of
// that direction (bit for bit) whose origins lie within `reach` of every vertex: each of them
// meets its back.
bool facesAwayAlong(const Triangle& triangle, const glm::dvec3& direction, double reach);
// Whether a single-sided triangle shows its front to every point of the box [endLo, endHi] by
// the same margin, for rays whose segments end in that box (a point or spot light's shadow
// rays end at the light, within rounding) and whose origins, ends and crossing points lie
// within `reach` of one another: each of them meets its back, or crosses its plane so far
// beyond its end that no hit there is reported.
bool facesTowardEnds(const Triangle& triangle, const glm::dvec3& endLo, const glm::dvec3& endHi, double reach);
// Whether the triangle lies outside one side plane of the frustum by more than the test's
// rounding can bridge: no ray inside the frustum can hit it.
bool outsideFrustum(const Triangle& triangle, const ViewFrustum& frustum);

// The skips `switches` allow for frame g (back faces need rays that share their start; the
// frustum needs g.frustum), on every thread of pool.
TriangleSkips skipTriangles(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool);

// g restricted to the kept triangles: tracedTriangles, the kept triangles' box and its margin.
// skips must outlive the result.
FrameGeometry withSkips(const FrameGeometry& g, const TriangleSkips& skips);

// What a skip's first pass over a chunk of triangles counted (pass_cull.cpp's too).
struct SkipTally {
    std::uint64_t kept = 0, backFacing = 0, outside = 0, singleSided = 0;
    Box box;  // the kept triangles' bounds
};
// The chunks of a skip's passes over `triangles`: up to 64, of at least 4096, and chunk c's range.
std::size_t skipChunks(std::size_t triangles);
std::pair<std::size_t, std::size_t> skipChunkRange(std::size_t c, std::size_t chunks, std::size_t triangles);
// A verdict byte of kTracedVerdict keeps the triangle.
constexpr std::uint8_t kTracedVerdict = 0;
// The chunks' tallies added into skips, and skips.traced filled with the kept ids, ascending,
// chunk by chunk in parallel (not where every triangle was kept, unless evenIfAllKept:
// skips.applied says which). Returns the tallies' `outside` total.
std::uint64_t listTraced(const std::vector<SkipTally>& tallies, const std::uint8_t* verdict, std::size_t triangles,
                         bool evenIfAllKept, ThreadPool& pool, TriangleSkips& skips);

// The skips' lines of the work plan.
void planSkips(const FrameGeometry& g, const SkipSwitches& switches, const TriangleSkips& skips, MemoryPlan& plan);

}  // namespace dacrt
