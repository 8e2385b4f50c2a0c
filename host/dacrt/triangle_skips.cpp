#include "dacrt/triangle_skips.hpp"

#include <algorithm>
#include <cmath>

namespace dacrt {
namespace {

constexpr double kFloatUnit = 0x1p-24;  // u: float32's unit roundoff

// 2^-12 of the triangle's distance: far beyond how far from a triangle the watertight test
// can place a hit (a few units in the last place of that distance, docs/correctness.md).
constexpr double kFrustumSlack = 0x1p-12;

enum class Verdict : std::uint8_t { Traced, BackFacing, OutsideFrustum };

}  // namespace

bool facesAwayFrom(const Triangle& t, const glm::dvec3& origin) {
    const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
    const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
    const double side = glm::dot(n, p0 - origin);  // > 0: the origin sees the back
    if (!(side > 0.0)) return false;
    const double reach = std::max({glm::length(p0 - origin), glm::length(p1 - origin), glm::length(p2 - origin)});
    const double edge = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
    // The test's determinant for a ray from origin that it accepts is side / (|P - O| d_kz)
    // in exact arithmetic (P the crossing, d the unit direction) and carries a rounding error
    // below 120 u reach (edge reach + edge^2 + u reach^2) (docs/correctness.md, "Skips"); past
    // twice that bound its sign is the exact one, which is "back".
    const double bound = 256.0 * kFloatUnit * reach * (edge * reach + edge * edge + kFloatUnit * reach * reach);
    return side > bound;
}

bool outsideFrustum(const Triangle& t, const ViewFrustum& f) {
    const glm::dvec3 p[3] = {glm::dvec3(t.v0) - f.apex, glm::dvec3(t.v1) - f.apex, glm::dvec3(t.v2) - f.apex};
    const double reach = std::max({glm::length(p[0]), glm::length(p[1]), glm::length(p[2])});
    const double slack = kFrustumSlack * reach;
    for (const glm::dvec3& n : f.inward)
        if (glm::dot(n, p[0]) < -slack && glm::dot(n, p[1]) < -slack && glm::dot(n, p[2]) < -slack) return true;
    return false;
}

TriangleSkips skipTriangles(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool) {
    TriangleSkips s;
    const std::vector<Triangle>& tris = *g.triangles;
    s.singleSided = singleSidedTriangles(tris);
    const bool backFaces = switches.backFaces && g.raysShareStart && s.singleSided > 0;
    const bool frustum = switches.frustum && g.frustum && g.raysShareStart;
    if (!backFaces && !frustum) return s;

    const glm::dvec3 origin(g.rayOrigin);
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, tris.size() / 4096 + 1));
    std::vector<Verdict> verdict(tris.size());
    std::vector<std::uint64_t> kept(chunks, 0), away(chunks, 0), outside(chunks, 0);
    std::vector<Box> boxes(chunks);
    auto range = [&](std::size_t c) {
        return std::pair<std::size_t, std::size_t>(tris.size() * c / chunks, tris.size() * (c + 1) / chunks);
    };
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = range(c);
        for (std::size_t i = begin; i < end; ++i) {
            Verdict v = Verdict::Traced;
            if (backFaces && tris[i].cullBackFace && facesAwayFrom(tris[i], origin))
                v = Verdict::BackFacing, ++away[c];
            else if (frustum && outsideFrustum(tris[i], *g.frustum))
                v = Verdict::OutsideFrustum, ++outside[c];
            else {
                ++kept[c];
                const Bounds& b = (*g.triangleBounds)[i];
                boxes[c].extend(b.lo);
                boxes[c].extend(b.hi);
            }
            verdict[i] = v;
        }
    });
    std::vector<std::uint64_t> offset(chunks, 0);
    std::uint64_t total = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
        offset[c] = total;
        total += kept[c];
        s.backFacing += away[c];
        s.outsideFrustum += outside[c];
        if (!boxes[c].empty()) s.tracedBox.extend(boxes[c].lo), s.tracedBox.extend(boxes[c].hi);
    }
    s.applied = true;
    s.traced.resize(total);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = range(c);
        std::uint64_t k = offset[c];
        for (std::size_t i = begin; i < end; ++i)
            if (verdict[i] == Verdict::Traced) s.traced[k++] = std::uint32_t(i);
    });
    return s;
}

FrameGeometry withSkips(const FrameGeometry& g, const TriangleSkips& skips) {
    if (!skips.applied || skips.traced.empty()) return g;
    FrameGeometry r = g;
    r.tracedTriangles = &skips.traced;
    r.sceneBox = skips.tracedBox;
    r.margin = filterMargin(r.sceneBox, r.rayOrigin);
    return r;
}

void planSkips(const FrameGeometry& g, const SkipSwitches& switches, const TriangleSkips& skips, MemoryPlan& plan) {
    plan.addWork("triangles", g.triangles->size(), "after the loader dropped those with no area");
    plan.addWork("single-sided triangles", skips.singleSided, "back faces culled (--cull)");
    auto reason = [&](bool on, bool possible, const char* needs) {
        return std::string(!on ? "skip off (--no-skip)" : !possible ? needs : "");
    };
    plan.addWork("skipped: back-facing", skips.backFacing,
                 skips.applied && switches.backFaces && g.raysShareStart
                     ? "single-sided, facing away from the rays' shared origin"
                     : reason(switches.backFaces, g.raysShareStart && skips.singleSided, "needs rays with one origin and single-sided triangles"));
    plan.addWork("skipped: outside the view frustum", skips.outsideFrustum,
                 skips.applied && switches.frustum && g.frustum ? "no primary ray of the camera can reach them"
                                                                : reason(switches.frustum, bool(g.frustum), "needs a camera's primary rays"));
    plan.addWork("triangles traced", skips.applied ? skips.traced.size() : g.triangles->size());
    plan.addWork("rays", g.rays->size());
}

}  // namespace dacrt
