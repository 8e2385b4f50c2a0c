#include "cpu/triangle_skips.hpp"

#include "core/mapped_memory.hpp"
#include "cpu/simd_kernels.hpp"

#include <algorithm>
#include <cmath>

namespace dacrt {
namespace {

// 2^-12 of the triangle's distance: far beyond how far from a triangle the watertight test
// can place a hit (a few units in the last place of that distance, docs/correctness.md).
constexpr double kFrustumSlack = 0x1p-12;

enum class Verdict : std::uint8_t { Traced = kTracedVerdict, BackFacing, OutsideFrustum };

// L^2 of the facing tests' bounds: the longest of a triangle's three edges, squared.
double longestEdgeSquared(const glm::dvec3& e1, const glm::dvec3& e2, const glm::dvec3& e3) {
    return std::max({glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3)});
}

}  // namespace

bool facesAwayFrom(const Triangle& t, const glm::dvec3& origin) {
    const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, e3 = p2 - p1;
    const glm::dvec3 a = p0 - origin, b = p1 - origin, c = p2 - origin;
    const double side = glm::dot(glm::cross(e1, e2), a);  // > 0: the origin sees the back
    if (!(side > 0.0)) return false;
    // With R the largest distance from the origin to a vertex and L the longest edge, the
    // test's determinant for a ray from the origin that it accepts is at least side / R in
    // magnitude (exact arithmetic) and carries a rounding error below
    // 96 u L R + 72 u L^2 + 100 u^2 R^2 (docs/correctness.md, "Skips"); its sign is the exact
    // one, "back", where side / R^2 > 240 u L + 100 u^2 R (L <= 2R), required twice over.
    const double r2 = std::max({glm::dot(a, a), glm::dot(b, b), glm::dot(c, c)});
    const double l2 = longestEdgeSquared(e1, e2, e3);
    return side / r2 > kFacingPerEdge * std::sqrt(l2) + kFacingPerReach * std::sqrt(r2);
}

bool facesAwayAlong(const Triangle& t, const glm::dvec3& direction, double reach) {
    const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, e3 = p2 - p1;
    // The exact determinant of a ray along `direction` is at least n . d / |d| in magnitude,
    // whatever its origin; its rounding error is facesAwayFrom's, with R = reach.
    const double along = glm::dot(glm::cross(e1, e2), direction) / glm::length(direction);
    if (!(along > 0.0)) return false;
    const double l2 = longestEdgeSquared(e1, e2, e3);
    return along / reach > kFacingPerEdge * std::sqrt(l2) + kFacingPerReach * reach;
}

bool facesTowardEnds(const Triangle& t, const glm::dvec3& endLo, const glm::dvec3& endHi, double reach) {
    const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
    const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0, e3 = p2 - p1;
    const glm::dvec3 n = glm::cross(e1, e2);
    // The least of n . (E - v0) over the box's points E is at its corner lowest along n. A ray
    // ending at E that crosses the plane at X before its end has n . d (tmax - t) = n . (E - X),
    // so n . d > 0, and |n . d| / |d| = n . (E - v0) / |E - X|: the bound of facesAwayFrom with
    // the end for the origin and R = reach. One that crosses it beyond its end stays on the
    // front side, farther from the plane than a reported hit can be from its triangle
    // (docs/correctness.md, "Skips").
    const glm::dvec3 lowest(n.x > 0.0 ? endLo.x : endHi.x, n.y > 0.0 ? endLo.y : endHi.y, n.z > 0.0 ? endLo.z : endHi.z);
    const double side = glm::dot(n, lowest - p0);
    if (!(side > 0.0)) return false;
    const double l2 = longestEdgeSquared(e1, e2, e3);
    return side / (reach * reach) > kFacingPerEdge * std::sqrt(l2) + kFacingPerReach * reach;
}

bool outsideFrustum(const Triangle& t, const ViewFrustum& f) {
    const glm::dvec3 p[3] = {glm::dvec3(t.v0) - f.apex, glm::dvec3(t.v1) - f.apex, glm::dvec3(t.v2) - f.apex};
    // Outside a plane by more than kFrustumSlack R, R the largest vertex distance, in squares.
    const double r2 = std::max({glm::dot(p[0], p[0]), glm::dot(p[1], p[1]), glm::dot(p[2], p[2])});
    const double slack2 = kFrustumSlack * kFrustumSlack * r2;
    auto beyond = [&](const glm::dvec3& n, const glm::dvec3& v) {
        const double d = glm::dot(n, v);
        return d < 0.0 && d * d > slack2;
    };
    for (const glm::dvec3& n : f.inward)
        if (beyond(n, p[0]) && beyond(n, p[1]) && beyond(n, p[2])) return true;
    return false;
}

namespace {

// box.extend(t.v0), box.extend(t.v1), box.extend(t.v2) where `kept`, else nothing, as
// box.extend(the triangle's own minimum), box.extend(its maximum): each glm::min and glm::max
// keeps its first operand on a tie, so either way the first of equal values in the order
// chunk, triangle, vertex wins (a zero's sign included), and the box has the same bits.
// Where not kept, the triangle's bounds are replaced by an empty box's, which changes nothing.
inline void extendByTriangle(Box& box, const Triangle& t, bool kept) {
    const glm::vec3 lo = glm::min(glm::min(t.v0, t.v1), t.v2), hi = glm::max(glm::max(t.v0, t.v1), t.v2);
    const Box empty;
    box.lo = glm::min(box.lo, kept ? lo : empty.lo);
    box.hi = glm::max(box.hi, kept ? hi : empty.hi);
}

// Whether the whole box lies inside the frustum with room to spare: then no triangle in it is
// outside, and the per-triangle test is skipped.
bool frustumHolds(const ViewFrustum& f, const Box& box) {
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
        const glm::dvec3 v = corner - f.apex;
        for (const glm::dvec3& n : f.inward)
            if (!(glm::dot(n, v) > 0.0)) return false;
    }
    return true;
}

}  // namespace

TriangleSkips skipTriangles(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool) {
    TriangleSkips s;
    const std::vector<Triangle>& tris = *g.triangles;
    const bool backFaces = switches.backFaces && g.raysShareStart;
    const bool frustum = switches.frustum && g.frustum && g.raysShareStart && !frustumHolds(*g.frustum, g.sceneBox);
    s.frustumTested = frustum;
    if (!backFaces && !frustum) return s;  // not even counted: a frame with the skips off pays nothing

    const glm::dvec3 origin(g.rayOrigin);
    const std::size_t chunks = skipChunks(tris.size());
    std::vector<std::uint8_t> verdict(tris.size());
    std::vector<SkipTally> tallies(chunks);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = skipChunkRange(c, chunks, tris.size());
        // Counted locally: neighbouring chunks' counters share cache lines.
        SkipTally tally;
        // The facing of the chunk's triangles in SIMD lanes first; facesAwayFrom where they
        // cannot tell.
        std::vector<std::uint8_t> facing(end - begin, backFaces ? simd::kUndecided : simd::kKeep);
        if (backFaces && end - begin <= simd::kMaxTriangles)
            simd::classifyFacing(tris.data() + begin, std::uint32_t(end - begin), g.rayOrigin, facing.data());
        // The verdicts, counts and box by arithmetic on each triangle's outcome rather than
        // branches on it (half the single-sided triangles of a closed mesh face away: a coin
        // toss a triangle), and the box through the triangle's own bounds, so that its chain
        // of dependent minima and maxima is one long a triangle, not three.
        for (std::size_t i = begin; i < end; ++i) {
            const Triangle& t = tris[i];
            const std::uint8_t f = facing[i - begin];
            const bool singleSided = t.cullBackFace != 0u;
            const bool back = (f == simd::kDrop) | (f == simd::kUndecided && singleSided && facesAwayFrom(t, origin));
            const bool outside = !back && frustum && outsideFrustum(t, *g.frustum);
            const bool kept = !back && !outside;
            tally.singleSided += singleSided;
            tally.backFacing += back;
            tally.outside += outside;
            tally.kept += kept;
            extendByTriangle(tally.box, t, kept);  // the triangle's bounds, without reading them
            static_assert(std::uint8_t(Verdict::BackFacing) == 1 && std::uint8_t(Verdict::OutsideFrustum) == 2);
            verdict[i] = std::uint8_t(std::uint8_t(back) | std::uint8_t(outside) << 1);
        }
        tallies[c] = tally;
    });
    s.outsideFrustum = listTraced(tallies, verdict.data(), tris.size(), true, pool, s);
    return s;
}

std::size_t skipChunks(std::size_t triangles) {
    return std::max<std::size_t>(1, std::min<std::size_t>(64, triangles / 4096 + 1));
}

std::pair<std::size_t, std::size_t> skipChunkRange(std::size_t c, std::size_t chunks, std::size_t triangles) {
    return {triangles * c / chunks, triangles * (c + 1) / chunks};
}

std::uint64_t listTraced(const std::vector<SkipTally>& tallies, const std::uint8_t* verdict, std::size_t triangles,
                         bool evenIfAllKept, ThreadPool& pool, TriangleSkips& s) {
    const std::size_t chunks = tallies.size();
    std::vector<std::uint64_t> offset(chunks, 0);
    std::uint64_t total = 0, outside = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
        const SkipTally& t = tallies[c];
        offset[c] = total;
        total += t.kept;
        s.backFacing += t.backFacing;
        outside += t.outside;
        s.singleSided += t.singleSided;
        if (!t.box.empty()) s.tracedBox.extend(t.box.lo), s.tracedBox.extend(t.box.hi);
    }
    s.applied = evenIfAllKept || total < triangles;
    if (!s.applied) return outside;
    resizeMapped(s.traced, total);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = skipChunkRange(c, chunks, triangles);
        // Every id written at the next place, which moves on where the id is kept (no branch
        // on the verdict); the chunk's last kept id ends the loop, so that no write passes
        // the chunk's own places.
        std::uint64_t k = offset[c];
        const std::uint64_t chunkEnd = c + 1 < chunks ? offset[c + 1] : total;
        for (std::size_t i = begin; i < end && k < chunkEnd; ++i) {
            s.traced[k] = std::uint32_t(i);
            k += verdict[i] == kTracedVerdict;
        }
    });
    return outside;
}

FrameGeometry withSkips(const FrameGeometry& g, const TriangleSkips& skips) {
    if (!skips.applied || skips.traced.empty()) return g;
    FrameGeometry r = g;
    r.tracedTriangles = &skips.traced;
    r.sceneBox = skips.tracedBox;
    r.margin = filterMargin(r.sceneBox, r.farthestOrigin);
    return r;
}

void planSkips(const FrameGeometry& g, const SkipSwitches& switches, const TriangleSkips& skips, MemoryPlan& plan) {
    plan.addWork("triangles", g.triangles->size(), "after the loader dropped those with no area");
    if (skips.applied) plan.addWork("single-sided triangles", skips.singleSided, "back faces culled (--cull)");
    auto reason = [&](bool on, bool possible, const char* needs) {
        return std::string(!on ? "skip off (--no-skip)" : !possible ? needs : "");
    };
    plan.addWork("skipped: back-facing", skips.backFacing,
                 skips.applied && switches.backFaces && g.raysShareStart
                     ? "single-sided, facing away from the rays' shared origin"
                     : reason(switches.backFaces, g.raysShareStart && skips.singleSided, "needs rays with one origin and single-sided triangles"));
    plan.addWork("skipped: outside the view frustum", skips.outsideFrustum,
                 skips.frustumTested ? "no primary ray of the camera can reach them"
                 : switches.frustum && g.frustum ? "none tested: the scene box lies inside the view"
                                                 : reason(switches.frustum, bool(g.frustum), "needs a pinhole camera's primary rays (an orthographic view has no apex)"));
    plan.addWork("triangles traced", skips.applied ? skips.traced.size() : g.triangles->size());
    plan.addWork("rays", g.rays->size());
}

}  // namespace dacrt
