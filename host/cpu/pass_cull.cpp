#include "cpu/pass_cull.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>

namespace dacrt {
namespace {

// Boxes over more rows of cells than this are kept without looking (large triangles are few).
constexpr int kMostRowsLooked = 64;

// Pieces of segment the grid marks per triangle of the scene, at most: the grid's resolution
// is chosen so that marking costs a fraction of the pass over the triangles (measured:
// docs/benchmarks.md, "Secondary passes").
constexpr double kPiecesPerTriangle = 0.5;

// The grid is marked for passes of fewer rays than this many triangles each. Since the
// Dragon's passes filter the triangles once as subtrees, from columns, a pass of its shadow
// rays of 15-16k rays (56 triangles each) or its merged passes of 93k (9 each) lose more to
// marking than the triangles it drops save; a shadow pass of 3.8-8.5k (100-230 each) still
// gains (docs/benchmarks.md, "Subtrees side by side, bounds in columns").
constexpr std::size_t kTrianglesPerRayForTheGrid = 64;

// Whether marking the grid for a pass of `rays` rays pays for itself.
bool gridPaysFor(std::uint64_t rays, std::size_t triangles) { return rays * kTrianglesPerRayForTheGrid < triangles; }

// Rays whose segments' lengths the grid's resolution is chosen from.
constexpr std::size_t kSpanSamples = 4096;

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

// Calls scan(begin, end, c) for the chunks c of a pass over `count` rays (up to 64, of at least
// 4096 rays) on the pool's threads, or as one chunk on the calling thread without a pool.
// Returns how many chunks there are.
template <typename Scan>
std::size_t scanRayChunks(std::size_t count, ThreadPool* pool, Scan&& scan) {
    const std::size_t chunks = pool ? std::max<std::size_t>(1, std::min<std::size_t>(64, count / 4096 + 1)) : 1;
    auto chunk = [&](std::size_t c, unsigned) { scan(count * c / chunks, count * (c + 1) / chunks, c); };
    if (pool)
        pool->parallelFor(chunks, chunk);
    else
        chunk(0, 0);
    return chunks;
}

// Whether every ray has the first one's direction, bit for bit (the back-face test's exactness
// rests on it): each chunk stops at its first other direction, so a pass of scattered
// directions (occlusion rays) reads a few rays only.
bool raysShareDirection(std::span<const Ray> rays, ThreadPool* pool) {
    return firstFailureInChunks(rays.size(), 4096, pool, [&](std::size_t i) {
               return std::memcmp(&rays[i].dir, &rays.front().dir, sizeof(Ray::dir)) == 0;
           }) == rays.size();
}

// The box of the rays' origins (the back-face tests' reach rests on every one of them).
PointBox originsOf(std::span<const Ray> rays, ThreadPool* pool) {
    std::vector<PointBox> parts(64);
    const std::size_t chunks = scanRayChunks(rays.size(), pool, [&](std::size_t begin, std::size_t end, std::size_t c) {
        PointBox box;  // in a local, written once: neighbouring chunks' boxes share cache lines
        for (std::size_t i = begin; i < end; ++i) box.extend(glm::dvec3(rays[i].origin));
        parts[c] = box;
    });
    for (std::size_t c = 1; c < chunks; ++c) parts[0].extend(parts[c]);
    return parts[0];
}

// Where every ray's segment ends, origin + tmax dir: shared where every ray has the same finite
// tmax and every end lies within kEndSpread of the scene's diagonal of the first ray's end
// along every axis (a point or spot light's shadow rays end at the light, within rounding).
// A chunk stops at its first end too far. The box of the ends holds the exact ones: each is
// one rounding of exact terms (tmax dir is exact in float64), so a step outwards covers it.
// The origins' box comes from the same pass.
constexpr double kEndSpread = 0x1p-10;
struct SharedEnd {
    bool shared = false;
    PointBox ends, origins;
};

// The shared end of rays whose ends' box is `end.ends`: shared, the box a float64 step wider on
// every side, so that it holds the exact ends (each is one rounding of exact terms: tmax dir is
// exact in float64).
SharedEnd endsShared(SharedEnd end) {
    end.shared = true;
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) end.ends.lo[a] = std::nextafter(end.ends.lo[a], -inf), end.ends.hi[a] = std::nextafter(end.ends.hi[a], inf);
    return end;
}
SharedEnd raysShareEnd(std::span<const Ray> rays, const Box& sceneBox, ThreadPool* pool) {
    SharedEnd out;
    const float tmax = rays.front().tmax;
    if (!(tmax < kNoHitT)) return out;
    const double spread = kEndSpread * glm::length(glm::dvec3(sceneBox.hi) - glm::dvec3(sceneBox.lo));
    auto endOf = [&](const Ray& r) { return glm::dvec3(r.origin) + double(tmax) * glm::dvec3(r.dir); };
    const glm::dvec3 first = endOf(rays.front());
    std::vector<SharedEnd> parts(64);
    std::atomic<bool> shared{true};
    const std::size_t chunks = scanRayChunks(rays.size(), pool, [&](std::size_t begin, std::size_t end, std::size_t c) {
        SharedEnd part;  // in a local, as originsOf's
        for (std::size_t i = begin; i < end && shared.load(std::memory_order_relaxed); ++i) {
            const glm::dvec3 e = endOf(rays[i]), off = glm::abs(e - first);
            part.ends.extend(e);
            part.origins.extend(glm::dvec3(rays[i].origin));
            if (rays[i].tmax != tmax || !(std::max({off.x, off.y, off.z}) <= spread))
                shared.store(false, std::memory_order_relaxed);
        }
        parts[c] = part;
    });
    if (!shared.load()) return out;
    for (std::size_t c = 0; c < chunks; ++c) out.ends.extend(parts[c].ends), out.origins.extend(parts[c].origins);
    return endsShared(out);
}

// The survey's shared end, as raysShareEnd finds it over the same rays: every ray's tmax the
// first's and finite, and every end within the spread of the first's on every axis. Rounded
// subtraction is monotone, so the ends farthest from the first on an axis are the box's faces:
// the faces within the spread put every end within it.
SharedEnd sharedEndOf(const RaySurvey& survey, const Box& sceneBox) {
    SharedEnd out;
    if (survey.rays == 0 || !survey.sameTmax || !(survey.firstTmax < kNoHitT)) return out;
    const double spread = kEndSpread * glm::length(glm::dvec3(sceneBox.hi) - glm::dvec3(sceneBox.lo));
    const glm::dvec3 first = glm::dvec3(survey.firstOrigin) + double(survey.firstTmax) * glm::dvec3(survey.firstDir);
    for (int a = 0; a < 3; ++a)
        if (!(survey.ends.hi[a] - first[a] <= spread) || !(first[a] - survey.ends.lo[a] <= spread)) return out;
    out.ends = survey.ends;
    out.origins = survey.origins;
    return endsShared(out);
}

// The largest distance between a ray's origin, a point of the scene and a ray's end (where
// they share one): what bounds every distance the back-face tests' margins scale with.
double reachOf(PointBox origins, const Box& sceneBox, const SharedEnd& end) {
    origins.extend(glm::dvec3(sceneBox.lo));
    origins.extend(glm::dvec3(sceneBox.hi));
    if (end.shared) origins.extend(end.ends);
    return origins.diagonal();
}

// The clipped segments' lengths, in the box's longest side, estimated from a sample of the
// rays: what the grid's resolution is chosen from.
double segmentSpans(const std::vector<Ray>& rays, const glm::dvec3& clipLo, const glm::dvec3& clipHi) {
    const double longest = std::max({clipHi.x - clipLo.x, clipHi.y - clipLo.y, clipHi.z - clipLo.z});
    const std::size_t stride = std::max<std::size_t>(1, rays.size() / kSpanSamples);
    double spans = 0.0;
    for (std::size_t i = 0; i < rays.size(); i += stride) {
        const Interval iv = clipped(rays[i], clipLo, clipHi);
        if (iv.t0 <= iv.t1)
            spans += double(stride) * ((iv.t1 - iv.t0) * glm::length(glm::dvec3(rays[i].dir)) / longest +
                                       1.0 / RayGrid::kMaxCells);
    }
    return spans;
}

enum Verdict : std::uint8_t { kTraced = kTracedVerdict, kOutsideRays, kBackFacing };

}  // namespace

// Cells from..to of a row, as bits.
std::uint64_t rowBits(int from, int to) { return (~0ull >> (63 - to)) & (~0ull << from); }

void RayGrid::markCells(const CellSpan& cells) {
    const std::uint64_t bits = rowBits(cells.from[0], cells.to[0]);
    for (int z = cells.from[2]; z <= cells.to[2]; ++z)
        for (int y = cells.from[1]; y <= cells.to[1]; ++y) {
            std::atomic_ref<std::uint64_t> row(rows_[std::size_t(z) * axes_.count[1] + y]);
            if ((row.load(std::memory_order_relaxed) & bits) != bits) row.fetch_or(bits, std::memory_order_relaxed);
        }
}

void RayGrid::markRay(const Ray& ray, simd::PieceEndCells& ends) {
    const Interval iv = clipped(ray, clipLo_, clipHi_);
    if (!(iv.t0 <= iv.t1)) return;  // the segment misses the scene box: it hits nothing
    const glm::dvec3 o(ray.origin), d(ray.dir);
    // Pieces of at most one cell along every axis, each marked with the cells of its box grown
    // by twice the margin. The cells near a point are monotone in each coordinate, so a
    // piece's cells are those of its two ends joined, and each end's are found once, all of
    // them in SIMD lanes.
    double span = 0.0;
    for (int k = 0; k < 3; ++k)
        span = std::max(span, std::abs(d[axes_.axis[k]]) * (iv.t1 - iv.t0) * double(axes_.scale[k]));
    static_assert(4 * kMaxCells <= unsigned(simd::kMostPieces));
    const int pieces = int(std::clamp(std::ceil(span), 1.0, double(4 * kMaxCells)));
    simd::cellsNearPieceEnds(o, d, iv.t0, iv.t1, pieces, grow_, axes_, ends);
    for (int k = 1; k <= pieces; ++k) {
        CellSpan piece;
        for (int a = 0; a < 3; ++a) {
            piece.from[a] = std::min(ends.from[a][k - 1], ends.from[a][k]);
            piece.to[a] = std::max(ends.to[a][k - 1], ends.to[a][k]);
        }
        markCells(piece);
    }
}

void RayGrid::mark(const FrameGeometry& g, unsigned cellsAlongLongest, std::vector<std::uint64_t>& rows, ThreadPool& pool) {
    const Box& box = g.sceneBox;
    const glm::vec3 extent = box.extent();
    const int shortest = int(std::min_element(&extent[0], &extent[0] + 3) - &extent[0]);
    int* axis = axes_.axis;
    axis[0] = shortest, axis[1] = (shortest + 1) % 3, axis[2] = (shortest + 2) % 3;
    const double longest = std::max({extent.x, extent.y, extent.z});
    // Cubic cells, cellsAlongLongest along the longest side, no more than kWordCells along the
    // shortest (larger cells where it would take more).
    const double cell = std::max(longest / std::clamp(cellsAlongLongest, 1u, kMaxCells), double(extent[shortest]) / kWordCells);
    longest_ = 1;
    for (int k = 0; k < 3; ++k) {
        const int a = axis[k];
        int& n = axes_.count[k];
        n = cell > 0.0 ? std::clamp(int(std::ceil(double(extent[a]) / cell)), 1, int(k == 0 ? kWordCells : kMaxCells)) : 1;
        axes_.lo[k] = box.lo[a];
        axes_.scale[k] = extent[a] > 0.0f ? float(n) / extent[a] : 0.0f;
        longest_ = std::max(longest_, unsigned(n));
    }
    grow_ = 2.0 * double(g.margin);
    clipLo_ = glm::dvec3(box.lo) - grow_;
    clipHi_ = glm::dvec3(box.hi) + grow_;
    rows.assign(std::size_t(axes_.count[1]) * std::size_t(axes_.count[2]), 0);
    rows_ = rows.data();
    const std::vector<Ray>& rays = *g.rays;
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, rays.size() / 1024 + 1));
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        simd::PieceEndCells ends;
        for (std::size_t i = rays.size() * c / chunks, end = rays.size() * (c + 1) / chunks; i < end; ++i)
            markRay(rays[i], ends);
    });
}

bool RayGrid::meetsCells(const simd::BoxCells& cells, std::uint32_t i) const {
    const int x0 = cells.first[0][i], x1 = cells.last[0][i], y0 = cells.first[1][i], y1 = cells.last[1][i],
              z0 = cells.first[2][i], z1 = cells.last[2][i];
    const std::uint64_t bits = rowBits(x0, x1);
    auto row = [&](int y, int z) { return rows_[std::size_t(z) * axes_.count[1] + y]; };
    // Most triangles span at most two cells along y and z: their four rows, without a loop.
    if (y1 - y0 <= 1 && z1 - z0 <= 1) return ((row(y0, z0) | row(y1, z0) | row(y0, z1) | row(y1, z1)) & bits) != 0;
    if ((y1 - y0 + 1) * (z1 - z0 + 1) > kMostRowsLooked) return true;
    for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y)
            if (row(y, z) & bits) return true;
    return false;
}

namespace {

// What every ray of a pass shares that the back-face tests read: its direction, or the box
// its segments end in (end.shared), and the reach of the rays and the scene.
struct SharedFacing {
    glm::dvec3 direction{0.0};
    SharedEnd end;
    double reach = 0.0;
};

// backFacing[j] for the block's triangles: single-sided and facing away from the shared
// direction (in SIMD lanes) or toward the shared end, so that every ray meets its back, for
// the triangles asked for (all where asked is null; the others 0).
void facingOfBlock(const Triangle* tris, std::uint32_t count, const SharedFacing& facing, const std::uint8_t* asked,
                   std::uint8_t* backFacing) {
    if (!facing.end.shared) {
        simd::facingAwayAlong(tris, count, facing.direction, facing.reach, asked, backFacing);
        return;
    }
    for (std::uint32_t j = 0; j < count; ++j)
        backFacing[j] = (!asked || asked[j]) && tris[j].cullBackFace &&
                        facesTowardEnds(tris[j], facing.end.ends.lo, facing.end.ends.hi, facing.reach);
}

// The verdicts, chunk by chunk (counts per chunk), then the kept ids in order: two passes
// over the triangles, into the cull's reused buffers.
void keepTriangles(const FrameGeometry& g, const RayGrid* grid, const SharedFacing* facing, ThreadPool& pool,
                   PassCull& cull) {
    const std::vector<Triangle>& tris = *g.triangles;
    const std::vector<Bounds>& bounds = *g.triangleBounds;
    const std::size_t chunks = skipChunks(tris.size());
    cull.verdict.resize(tris.size());
    std::vector<SkipTally> tallies(chunks);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = skipChunkRange(c, chunks, tris.size());
        SkipTally tally;
        // Block by block: the cells and the facing in SIMD lanes (cull_lanes.hpp), then each
        // triangle's verdict from their answers, still in the first level of cache.
        simd::BoxCells cells;
        std::uint8_t meets[simd::kCullBlock], backFacing[simd::kCullBlock];
        for (std::size_t block = begin; block < end; block += simd::kCullBlock) {
            const auto count = std::uint32_t(std::min<std::size_t>(simd::kCullBlock, end - block));
            if (grid) {
                simd::cellsOfBoxes(bounds.data() + block, count, grid->axes(), cells);
                for (std::uint32_t j = 0; j < count; ++j) meets[j] = grid->meetsCells(cells, j);
            }
            // Only the triangles the grid keeps are read.
            if (facing) facingOfBlock(tris.data() + block, count, *facing, grid ? meets : nullptr, backFacing);
            for (std::uint32_t j = 0; j < count; ++j) {
                const std::size_t i = block + j;
                Verdict v = kTraced;
                if (grid && !meets[j])
                    v = kOutsideRays, ++tally.outside;
                else if (facing && backFacing[j])
                    v = kBackFacing, ++tally.backFacing;
                else {
                    ++tally.kept;
                    tally.box.extend(bounds[i].lo);
                    tally.box.extend(bounds[i].hi);
                }
                cull.verdict[i] = v;
            }
        }
        tallies[c] = tally;
    });
    // Where nothing was dropped the pass traces every triangle, unlisted.
    cull.outsideRays = listTraced(tallies, cull.verdict.data(), tris.size(), false, pool, cull.skips);
}

// Whether the grid is marked for a pass of `rays` rays.
bool gridOnFor(std::size_t rays, std::size_t triangles, const SkipSwitches& switches, unsigned cellsAlongLongest) {
    return switches.passRays && (cellsAlongLongest || gridPaysFor(rays, triangles));
}

}  // namespace

void cullNothing(PassCull& cull) {
    cull.skips.applied = false;
    cull.skips.tracedBox = Box{};
    cull.skips.singleSided = cull.skips.backFacing = cull.skips.outsideFrustum = 0;
    cull.outsideRays = 0;
    cull.raysTested = cull.directionShared = cull.endShared = false;
    cull.cellsAlongLongest = 0;
}

bool passCullTests(const std::vector<Ray>& rays, std::size_t triangles, const Box& sceneBox, const SkipSwitches& switches,
                   unsigned cellsAlongLongest) {
    if (rays.empty() || triangles == 0) return false;
    if (gridOnFor(rays.size(), triangles, switches, cellsAlongLongest)) return true;
    if (!switches.backFaces) return false;
    // The first rays only, on this thread: cullForPass asks every one.
    const std::span<const Ray> first(rays.data(), std::min<std::size_t>(rays.size(), 64));
    return raysShareDirection(first, nullptr) || raysShareEnd(first, sceneBox, nullptr).shared;
}

void RaySurvey::add(const Ray& ray) {
    if (rays == 0) {
        firstOrigin = ray.origin;
        firstDir = ray.dir;
        firstTmax = ray.tmax;
    } else {
        sameDirection = sameDirection && std::memcmp(&ray.dir, &firstDir, sizeof(Ray::dir)) == 0;
        sameTmax = sameTmax && ray.tmax == firstTmax;
    }
    ++rays;
    const glm::dvec3 origin(ray.origin);
    origins.extend(origin);
    ends.extend(origin + double(ray.tmax) * glm::dvec3(ray.dir));
}

void RaySurvey::merge(const RaySurvey& later) {
    if (later.rays == 0) return;
    if (rays == 0) {
        *this = later;
        return;
    }
    sameDirection = sameDirection && later.sameDirection && std::memcmp(&later.firstDir, &firstDir, sizeof(Ray::dir)) == 0;
    sameTmax = sameTmax && later.sameTmax && later.firstTmax == firstTmax;
    rays += later.rays;
    origins.extend(later.origins);
    ends.extend(later.ends);
}

void cullFromSurvey(const FrameGeometry& g, const RaySurvey& survey, const SkipSwitches& switches, ThreadPool& pool,
                    PassCull& cull) {
    cullNothing(cull);
    if (survey.rays == 0 || g.triangles->empty() || !switches.backFaces) return;
    cull.directionShared = survey.sameDirection;
    SharedFacing facing;
    if (!cull.directionShared) facing.end = sharedEndOf(survey, g.sceneBox);
    cull.endShared = facing.end.shared;
    if (!cull.directionShared && !cull.endShared) return;
    facing.direction = glm::dvec3(survey.firstDir);
    facing.reach = reachOf(survey.origins, g.sceneBox, facing.end);
    keepTriangles(g, nullptr, &facing, pool, cull);
}

void cullForPass(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool, PassCull& cull,
                 unsigned cellsAlongLongest) {
    cullNothing(cull);
    const std::vector<Ray>& rays = *g.rays;
    if (rays.empty() || g.triangles->empty()) return;
    // Each test only where it may drop something, and the rays read only for the tests on: a
    // pass of many rays and scattered directions (occlusion) reads a few of them and no
    // triangle at all.
    const bool gridOn = gridOnFor(rays.size(), g.triangles->size(), switches, cellsAlongLongest);
    cull.directionShared = switches.backFaces && raysShareDirection(rays, &pool);
    SharedFacing facing;
    if (switches.backFaces && !cull.directionShared) facing.end = raysShareEnd(rays, g.sceneBox, &pool);
    cull.endShared = facing.end.shared;
    if (!gridOn && !cull.directionShared && !cull.endShared) return;  // every triangle traced, unlisted
    RayGrid grid;
    if (gridOn) {
        // Cells along the longest side: as many as the marking budget allows, up to kMaxCells.
        const double grow = 2.0 * double(g.margin);
        const double spans = segmentSpans(rays, glm::dvec3(g.sceneBox.lo) - grow, glm::dvec3(g.sceneBox.hi) + grow);
        const double budget = kPiecesPerTriangle * double(g.triangles->size());
        const double cells = std::clamp(budget / std::max(spans, 1e-30), 1.0, double(RayGrid::kMaxCells));
        grid.mark(g, cellsAlongLongest ? cellsAlongLongest : unsigned(cells), cull.rows, pool);
        cull.raysTested = true;
        cull.cellsAlongLongest = grid.cellsAlongLongest();
    }
    facing.direction = glm::dvec3(rays.front().dir);
    if (cull.directionShared) facing.reach = reachOf(originsOf(rays, &pool), g.sceneBox, facing.end);
    if (cull.endShared) facing.reach = reachOf(facing.end.origins, g.sceneBox, facing.end);
    keepTriangles(g, cull.raysTested ? &grid : nullptr, cull.directionShared || cull.endShared ? &facing : nullptr, pool,
                  cull);
}

bool passCullMayDrop(std::uint64_t mostRays, std::size_t triangles, bool sharedFacing, const SkipSwitches& switches) {
    return (switches.passRays && gridPaysFor(mostRays, triangles)) || (switches.backFaces && sharedFacing);
}

void planPassCull(const FrameGeometry& g, const SkipSwitches& switches, const PassCull& cull, MemoryPlan& plan) {
    plan.addWork("skipped: outside the pass's rays' bounds", cull.outsideRays,
                 cull.raysTested ? "no segment of the pass's rays passes their cells (" +
                                       std::to_string(cull.cellsAlongLongest) + " cells along the scene's longest side)"
                 : switches.passRays ? "none tested: too many rays for the triangles to pay for the grid"
                                     : "skip off (--no-skip)");
    plan.addWork("skipped: back-facing", cull.skips.backFacing,
                 cull.directionShared ? "single-sided, facing away from the rays' shared direction"
                 : cull.endShared      ? "single-sided, facing toward the point where every ray ends"
                 : !switches.backFaces ? "skip off (--no-skip)"
                                       : "needs rays with one direction or one end (a light's)");
    plan.addWork("triangles traced", cull.skips.applied ? cull.skips.traced.size() : g.triangles->size());
}

}  // namespace dacrt
