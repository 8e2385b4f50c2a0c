#include "cpu/pass_cull.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

namespace dacrt {
namespace {

// Boxes over more rows of cells than this are kept without looking (large triangles are few).
constexpr int kMostRowsLooked = 64;

// Pieces of segment the grid marks per triangle of the scene, at most: the grid's resolution
// is chosen so that marking costs a fraction of the pass over the triangles (measured:
// docs/benchmarks.md, "Secondary passes").
constexpr double kPiecesPerTriangle = 0.5;

// The grid is marked for passes of fewer rays than this many triangles each: the Dragon's
// occlusion pass (192,048 rays, 4.5 triangles each) lost more to marking than the 12% of
// triangles it dropped saved; its shadow pass (42,331 rays, 21 each) gained.
constexpr std::size_t kTrianglesPerRayForTheGrid = 8;

// Whether marking the grid for a pass of `rays` rays pays for itself.
bool gridPaysFor(std::uint64_t rays, std::size_t triangles) { return rays * kTrianglesPerRayForTheGrid < triangles; }

// Rays whose segments' lengths the grid's resolution is chosen from.
constexpr std::size_t kSurveySamples = 4096;

// The parameters [t0, t1] of the ray's segment inside [lo, hi], in float64 (empty: t0 > t1).
struct Interval {
    double t0, t1;
};
Interval clipped(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi) {
    Interval iv{ray.tmin, ray.tmax};
    for (int a = 0; a < 3; ++a) {
        const double o = ray.origin[a], d = ray.dir[a];
        if (d == 0.0) {
            if (o < lo[a] || o > hi[a]) return {1.0, 0.0};
            continue;
        }
        double near = (lo[a] - o) / d, far = (hi[a] - o) / d;
        if (near > far) std::swap(near, far);
        iv.t0 = std::max(iv.t0, near);
        iv.t1 = std::min(iv.t1, far);
    }
    return iv;
}

// The float next to f towards -inf, as std::nextafter (-FLT_MAX steps to -inf, which the
// grid's cellOf clamps to the cell FLT_MAX's direction would give).
std::int32_t floatBitsStepDown(std::int32_t bits) {
    bits = bits == 0 ? std::numeric_limits<std::int32_t>::min() : bits;  // +0 steps as -0 does
    return bits + (bits < 0 ? 1 : -1);
}

// The float nearest to x, stepped once towards -inf where it is above x: no float is between
// it and x. Without branches (a mask picks the step): the grid's marking asks for six a piece
// of segment, and whether a step is needed is a coin toss that a branch predictor loses
// (it cost the Dragon's shadow pass half of its marking time).
float floatBelow(double x) {
    const float f = float(x);
    const std::int32_t bits = std::bit_cast<std::int32_t>(f);
    const std::int32_t step = -std::int32_t(double(f) > x);
    return std::bit_cast<float>((floatBitsStepDown(bits) & step) | (bits & ~step));
}
// The same towards +inf: a float no less than x.
float floatAbove(double x) { return -floatBelow(-x); }

// What the cull learns from one pass over the rays.
struct RaySurvey {
    double cellSpans = 0.0;       // the clipped segments' lengths, in the box's longest side (estimated)
    glm::dvec3 originLo{kNoHitT}, originHi{-kNoHitT};
    bool directionShared = true;
};

// The origins' box and whether the directions agree, over every ray (the back-face test's
// exactness rests on both), in parallel; the segments' lengths from a sample of the rays.
RaySurvey surveyRays(const FrameGeometry& g, const glm::dvec3& clipLo, const glm::dvec3& clipHi, ThreadPool& pool) {
    const std::vector<Ray>& rays = *g.rays;
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, rays.size() / 4096 + 1));
    std::vector<RaySurvey> parts(chunks);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        RaySurvey s;
        for (std::size_t i = rays.size() * c / chunks, end = rays.size() * (c + 1) / chunks; i < end; ++i) {
            s.originLo = glm::min(s.originLo, glm::dvec3(rays[i].origin));
            s.originHi = glm::max(s.originHi, glm::dvec3(rays[i].origin));
            s.directionShared = s.directionShared && std::memcmp(&rays[i].dir, &rays.front().dir, sizeof(Ray::dir)) == 0;
        }
        parts[c] = s;
    });
    RaySurvey s;
    for (const RaySurvey& p : parts) {
        s.originLo = glm::min(s.originLo, p.originLo);
        s.originHi = glm::max(s.originHi, p.originHi);
        s.directionShared = s.directionShared && p.directionShared;
    }
    const double longest = std::max({clipHi.x - clipLo.x, clipHi.y - clipLo.y, clipHi.z - clipLo.z});
    const std::size_t stride = std::max<std::size_t>(1, rays.size() / kSurveySamples);
    for (std::size_t i = 0; i < rays.size(); i += stride) {
        const Interval iv = clipped(rays[i], clipLo, clipHi);
        if (iv.t0 <= iv.t1)
            s.cellSpans += double(stride) * ((iv.t1 - iv.t0) * glm::length(glm::dvec3(rays[i].dir)) / longest +
                                             1.0 / RayGrid::kMaxCells);
    }
    return s;
}

// The largest distance from a ray's origin to a point of the scene.
double farthestReach(const RaySurvey& s, const Box& sceneBox) {
    const glm::dvec3 lo = glm::min(s.originLo, glm::dvec3(sceneBox.lo)), hi = glm::max(s.originHi, glm::dvec3(sceneBox.hi));
    return glm::length(hi - lo);
}

enum Verdict : std::uint8_t { kTraced = kTracedVerdict, kOutsideRays, kBackFacing };

}  // namespace

int RayGrid::cellOf(float x, int k) const {
    // Monotone in x (each rounding and the clamp are), so boxes that overlap get cell ranges
    // that overlap. Branch-free: the triangles' pass calls it six times a triangle. std::max
    // with 0 first: an infinite x on a flat axis (scale 0) gives NaN, which it turns into 0.
    return int(std::min(std::max(0.0f, (x - lo_[k]) * scale_[k]), float(n_[k] - 1)));
}

// Cells from..to of a row, as bits.
std::uint64_t rowBits(int from, int to) { return (~0ull >> (63 - to)) & (~0ull << from); }

RayGrid::CellSpan RayGrid::cellsNear(const glm::dvec3& p) const {
    CellSpan span;
    for (int k = 0; k < 3; ++k) {
        span.from[k] = cellOf(floatBelow(p[axis_[k]] - grow_), k);
        span.to[k] = cellOf(floatAbove(p[axis_[k]] + grow_), k);
    }
    return span;
}

void RayGrid::markCells(const CellSpan& cells) {
    const std::uint64_t bits = rowBits(cells.from[0], cells.to[0]);
    for (int z = cells.from[2]; z <= cells.to[2]; ++z)
        for (int y = cells.from[1]; y <= cells.to[1]; ++y) {
            std::atomic_ref<std::uint64_t> row(rows_[std::size_t(z) * n_[1] + y]);
            if ((row.load(std::memory_order_relaxed) & bits) != bits) row.fetch_or(bits, std::memory_order_relaxed);
        }
}

void RayGrid::markRay(const Ray& ray) {
    const Interval iv = clipped(ray, clipLo_, clipHi_);
    if (!(iv.t0 <= iv.t1)) return;  // the segment misses the scene box: it hits nothing
    const glm::dvec3 o(ray.origin), d(ray.dir);
    // Pieces of at most one cell along every axis, each marked with the cells of its box grown
    // by twice the margin. cellsNear is monotone in each coordinate, so a piece's cells are
    // those of its two ends joined, and each end's are found once.
    double span = 0.0;
    for (int k = 0; k < 3; ++k) span = std::max(span, std::abs(d[axis_[k]]) * (iv.t1 - iv.t0) * double(scale_[k]));
    const int pieces = int(std::clamp(std::ceil(span), 1.0, double(4 * kMaxCells)));
    CellSpan from = cellsNear(o + iv.t0 * d);
    for (int k = 1; k <= pieces; ++k) {
        const double t = k == pieces ? iv.t1 : iv.t0 + (iv.t1 - iv.t0) * double(k) / double(pieces);
        const CellSpan to = cellsNear(o + t * d);
        CellSpan piece;
        for (int a = 0; a < 3; ++a) {
            piece.from[a] = std::min(from.from[a], to.from[a]);
            piece.to[a] = std::max(from.to[a], to.to[a]);
        }
        markCells(piece);
        from = to;
    }
}

void RayGrid::mark(const FrameGeometry& g, unsigned cellsAlongLongest, std::vector<std::uint64_t>& rows, ThreadPool& pool) {
    const Box& box = g.sceneBox;
    const glm::vec3 extent = box.extent();
    const int shortest = int(std::min_element(&extent[0], &extent[0] + 3) - &extent[0]);
    axis_[0] = shortest, axis_[1] = (shortest + 1) % 3, axis_[2] = (shortest + 2) % 3;
    const double longest = std::max({extent.x, extent.y, extent.z});
    // Cubic cells, cellsAlongLongest along the longest side, no more than kWordCells along the
    // shortest (larger cells where it would take more).
    const double cell = std::max(longest / std::clamp(cellsAlongLongest, 1u, kMaxCells), double(extent[shortest]) / kWordCells);
    longest_ = 1;
    for (int k = 0; k < 3; ++k) {
        const int a = axis_[k];
        n_[k] = cell > 0.0 ? std::clamp(int(std::ceil(double(extent[a]) / cell)), 1, int(k == 0 ? kWordCells : kMaxCells)) : 1;
        lo_[k] = box.lo[a];
        scale_[k] = extent[a] > 0.0f ? float(n_[k]) / extent[a] : 0.0f;
        longest_ = std::max(longest_, unsigned(n_[k]));
    }
    grow_ = 2.0 * double(g.margin);
    clipLo_ = glm::dvec3(box.lo) - grow_;
    clipHi_ = glm::dvec3(box.hi) + grow_;
    rows.assign(std::size_t(n_[1]) * std::size_t(n_[2]), 0);
    rows_ = rows.data();
    const std::vector<Ray>& rays = *g.rays;
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, rays.size() / 1024 + 1));
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        for (std::size_t i = rays.size() * c / chunks, end = rays.size() * (c + 1) / chunks; i < end; ++i) markRay(rays[i]);
    });
}

bool RayGrid::mayMeet(const glm::vec3& lo, const glm::vec3& hi) const {
    const int x0 = cellOf(lo[axis_[0]], 0), x1 = cellOf(hi[axis_[0]], 0), y0 = cellOf(lo[axis_[1]], 1),
              y1 = cellOf(hi[axis_[1]], 1), z0 = cellOf(lo[axis_[2]], 2), z1 = cellOf(hi[axis_[2]], 2);
    const std::uint64_t bits = rowBits(x0, x1);
    auto row = [&](int y, int z) { return rows_[std::size_t(z) * n_[1] + y]; };
    // Most triangles span at most two cells along y and z: their four rows, without a loop.
    if (y1 - y0 <= 1 && z1 - z0 <= 1) return ((row(y0, z0) | row(y1, z0) | row(y0, z1) | row(y1, z1)) & bits) != 0;
    if ((y1 - y0 + 1) * (z1 - z0 + 1) > kMostRowsLooked) return true;
    for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
            if (row(y, z) & bits) return true;
    return false;
}

namespace {

// The verdicts, chunk by chunk (counts per chunk), then the kept ids in order: two passes
// over the triangles, into the cull's reused buffers.
void keepTriangles(const FrameGeometry& g, const RayGrid* grid, const glm::dvec3* direction, double reach,
                   ThreadPool& pool, PassCull& cull) {
    const std::vector<Triangle>& tris = *g.triangles;
    const std::vector<Bounds>& bounds = *g.triangleBounds;
    const std::size_t chunks = skipChunks(tris.size());
    cull.verdict.resize(tris.size());
    std::vector<SkipTally> tallies(chunks);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = skipChunkRange(c, chunks, tris.size());
        SkipTally tally;
        for (std::size_t i = begin; i < end; ++i) {
            const Bounds& b = bounds[i];
            const Triangle& t = tris[i];
            Verdict v = kTraced;
            if (grid && !grid->mayMeet(b.lo, b.hi))
                v = kOutsideRays, ++tally.outside;
            else if (direction && t.cullBackFace && facesAwayAlong(t, *direction, reach))
                v = kBackFacing, ++tally.backFacing;
            else {
                ++tally.kept;
                tally.box.extend(b.lo);
                tally.box.extend(b.hi);
            }
            tally.singleSided += direction && t.cullBackFace != 0u;
            cull.verdict[i] = v;
        }
        tallies[c] = tally;
    });
    // Where nothing was dropped the pass traces every triangle, unlisted.
    cull.outsideRays = listTraced(tallies, cull.verdict.data(), tris.size(), false, pool, cull.skips);
}

}  // namespace

void cullForPass(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool, PassCull& cull,
                 unsigned cellsAlongLongest) {
    cull.skips.applied = false;
    cull.skips.tracedBox = Box{};
    cull.skips.singleSided = cull.skips.backFacing = cull.skips.outsideFrustum = 0;
    cull.outsideRays = 0;
    cull.raysTested = cull.directionShared = false;
    cull.cellsAlongLongest = 0;
    const std::vector<Ray>& rays = *g.rays;
    if ((!switches.passRays && !switches.backFaces) || rays.empty() || g.triangles->empty()) return;

    const double grow = 2.0 * double(g.margin);
    const RaySurvey survey = surveyRays(g, glm::dvec3(g.sceneBox.lo) - grow, glm::dvec3(g.sceneBox.hi) + grow, pool);
    RayGrid grid;
    // A pass of many rays for its triangles spends its time on the rays: the grid would cost
    // more than it saves (measured: docs/benchmarks.md, "Secondary passes").
    if (switches.passRays && (cellsAlongLongest || gridPaysFor(rays.size(), g.triangles->size()))) {
        // Cells along the longest side: as many as the marking budget allows, up to kMaxCells.
        const double budget = kPiecesPerTriangle * double(g.triangles->size());
        const double cells = std::clamp(budget / std::max(survey.cellSpans, 1e-30), 1.0, double(RayGrid::kMaxCells));
        grid.mark(g, cellsAlongLongest ? cellsAlongLongest : unsigned(cells), cull.rows, pool);
        cull.raysTested = true;
        cull.cellsAlongLongest = grid.cellsAlongLongest();
    }
    cull.directionShared = switches.backFaces && survey.directionShared;
    const glm::dvec3 direction(rays.front().dir);
    keepTriangles(g, cull.raysTested ? &grid : nullptr, cull.directionShared ? &direction : nullptr,
                  farthestReach(survey, g.sceneBox), pool, cull);
}

bool passCullMayDrop(std::uint64_t mostRays, std::size_t triangles, bool oneDirection, const SkipSwitches& switches) {
    return (switches.passRays && gridPaysFor(mostRays, triangles)) || (switches.backFaces && oneDirection);
}

void planPassCull(const FrameGeometry& g, const SkipSwitches& switches, const PassCull& cull, MemoryPlan& plan) {
    plan.addWork("skipped: outside the pass's rays' bounds", cull.outsideRays,
                 cull.raysTested ? "no segment of the pass's rays passes their cells (" +
                                       std::to_string(cull.cellsAlongLongest) + " cells along the scene's longest side)"
                 : switches.passRays ? "none tested: too many rays for the triangles to pay for the grid"
                                     : "skip off (--no-skip)");
    plan.addWork("skipped: back-facing", cull.skips.backFacing,
                 cull.directionShared ? "single-sided, facing away from the rays' shared direction"
                 : !switches.backFaces ? "skip off (--no-skip)"
                                       : "needs rays with one direction (a directional light's)");
    plan.addWork("triangles traced", cull.skips.applied ? cull.skips.traced.size() : g.triangles->size());
}

}  // namespace dacrt
