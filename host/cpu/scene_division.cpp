#include "cpu/predicates.hpp"
#include "cpu/scene_division.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace dacrt {
namespace {

constexpr std::uint32_t kCulled = 0xFFFFFFFFu;

// Where rays enter the scene box (a sample of them), as (entry point, entry face axis or -1
// for rays that start inside).
std::vector<std::pair<glm::vec3, int>> sampleEntries(const FrameGeometry& g, std::size_t maxSamples) {
    const std::vector<Ray>& rays = *g.rays;
    const Box& box = g.sceneBox;
    const std::size_t stride = std::max<std::size_t>(1, rays.size() / maxSamples);
    std::vector<std::pair<glm::vec3, int>> entries;
    for (std::size_t i = 0; i < rays.size(); i += stride) {
        const Ray& ray = rays[i];
        const shared::RayInterval iv = shared::rayBoxInterval(ray, box.lo, box.hi);
        if (!(iv.tNear <= iv.tFar && iv.tFar >= ray.tmin)) continue;
        int face = -1;
        float best = ray.tmin;
        for (int a = 0; a < 3; ++a) {
            if (ray.dir[a] == 0.0f) continue;
            const float t = std::min((box.lo[a] - ray.origin[a]) * ray.invDir[a], (box.hi[a] - ray.origin[a]) * ray.invDir[a]);
            if (t > best) best = t, face = a;
        }
        entries.emplace_back(ray.origin + std::max(iv.tNear, ray.tmin) * ray.dir, face);
    }
    return entries;
}

// Slab boundaries along the axis: equal widths (the source's midpoint subdivision,
// generalised to any n), boundary[0] = lo and boundary[n] = hi exactly.
std::vector<float> slabBoundaries(const Box& box, int axis, unsigned n) {
    std::vector<float> b(n + 1);
    const double lo = box.lo[axis], hi = box.hi[axis];
    for (unsigned k = 0; k <= n; ++k) b[k] = float(lo + (hi - lo) * double(k) / double(n));
    b[0] = box.lo[axis];
    b[n] = box.hi[axis];
    return b;
}

// The slab holding x (clamped to the ends); callers correct by walking.
int slabOf(float x, const std::vector<float>& boundary) {
    const int n = int(boundary.size()) - 1;
    const int k = int(std::upper_bound(boundary.begin() + 1, boundary.end() - 1, x) - (boundary.begin() + 1));
    return std::clamp(k, 0, n - 1);
}

}  // namespace

int chooseDivisionAxis(const FrameGeometry& g, unsigned regionCount) {
    const Box& box = g.sceneBox;
    const auto entries = sampleEntries(g, 8192);
    std::array<std::uint64_t, 3> entryFace{};
    for (const auto& e : entries)
        if (e.second >= 0) ++entryFace[std::size_t(e.second)];
    const glm::vec3 extent = box.extent();
    std::vector<int> candidates;
    const bool outside = entryFace[0] + entryFace[1] + entryFace[2] > 0;
    const int face = int(std::max_element(entryFace.begin(), entryFace.end()) - entryFace.begin());
    for (int a = 0; a < 3; ++a)
        if ((!outside || a != face) && extent[a] > 0.0f) candidates.push_back(a);
    if (candidates.empty()) return face;
    if (regionCount <= 1 || candidates.size() == 1 || entries.empty()) {
        return *std::max_element(candidates.begin(), candidates.end(),
                                 [&](int a, int b) { return extent[a] < extent[b]; });
    }
    const std::vector<Bounds>& tb = *g.triangleBounds;
    const std::size_t tracedCount = g.tracedTriangleCount();
    const std::size_t triStride = std::max<std::size_t>(1, tracedCount / 8192);
    int bestAxis = candidates.front();
    double bestCost = 1e300;
    for (int a : candidates) {
        const std::vector<float> boundary = slabBoundaries(box, a, regionCount);
        std::vector<double> rayShare(regionCount, 0.0), triShare(regionCount, 0.0);
        for (const auto& e : entries) rayShare[std::size_t(slabOf(e.first[a], boundary))] += 1.0;
        std::size_t triSamples = 0;
        for (std::size_t i = 0; i < tracedCount; i += triStride, ++triSamples) {
            const Bounds& b = tb[g.tracedTriangle(i)];
            triShare[std::size_t(slabOf(0.5f * (b.lo[a] + b.hi[a]), boundary))] += 1.0;
        }
        double cost = 0.0;
        for (unsigned k = 0; k < regionCount; ++k)
            cost = std::max(cost, rayShare[k] / double(entries.size()) + triShare[k] / double(triSamples));
        if (cost < bestCost - 1e-12 || (std::abs(cost - bestCost) <= 1e-12 && extent[a] > extent[bestAxis]))
            bestCost = cost, bestAxis = a;
    }
    return bestAxis;
}

Division divideScene(const FrameGeometry& g, unsigned n, int axis, ThreadPool& pool, MemoryPlan& plan,
                     const PlanHook& onPlan, const DivisionPlanHook& planTracer) {
    const std::vector<Ray>& rays = *g.rays;
    const std::vector<Bounds>& tb = *g.triangleBounds;
    const Box& box = g.sceneBox;
    const float m = g.margin;
    Division d;
    d.axis = axis;
    const std::vector<float> boundary = slabBoundaries(box, axis, n);
    d.regions.resize(n);
    std::vector<glm::vec3> wideLo(n), wideHi(n);  // the widened region boxes the filters use
    for (unsigned k = 0; k < n; ++k) {
        Region& r = d.regions[k];
        r = Region{};
        r.lo = box.lo;
        r.hi = box.hi;
        r.lo[axis] = boundary[k];
        r.hi[axis] = boundary[k + 1];
        wideLo[k] = r.lo - glm::vec3(m);
        wideHi[k] = r.hi + glm::vec3(m);
    }
    const glm::vec3 sceneLo = box.lo - glm::vec3(m), sceneHi = box.hi + glm::vec3(m);

    // Pass 1: which region each ray meets first, and per-chunk counts.
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, rays.size() / 4096 + 1));
    std::vector<std::uint32_t> rayRegion(rays.size());
    std::vector<std::uint32_t> rayCounts(chunks * n, 0);
    std::vector<std::uint8_t> chunkLow(chunks * n, 0), chunkHigh(chunks * n, 0);
    plan.add("ray region (binning)", std::uint64_t(rays.size()) * 4);
    auto chunkRange = [&](std::size_t c, std::size_t total) {
        return std::pair<std::size_t, std::size_t>(total * c / chunks, total * (c + 1) / chunks);
    };
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, rays.size());
        // Counted locally: neighbouring chunks' counters share cache lines.
        std::vector<std::uint32_t> counts(n, 0);
        std::vector<std::uint8_t> low(n, 0), high(n, 0);
        for (std::size_t i = begin; i < end; ++i) {
            const Ray& ray = rays[i];
            rayRegion[i] = kCulled;
            if (!shared::rayMayCrossCell(ray, sceneLo, sceneHi, kNoHitT)) continue;
            const float o = ray.origin[axis], dir = ray.dir[axis];
            const int step = dir < 0.0f ? -1 : 1;
            // Start one slab behind the origin's so that rounding in the guess never skips
            // the true first region; walk in the travel direction to the first one crossed.
            int k = slabOf(o, boundary) - step;
            if (dir > 0.0f && o < box.lo[axis]) k = 0;
            if (dir < 0.0f && o > box.hi[axis]) k = int(n) - 1;
            k = std::clamp(k, 0, int(n) - 1);
            for (; k >= 0 && k < int(n); k += step) {
                if (shared::rayMayCrossCell(ray, wideLo[std::size_t(k)], wideHi[std::size_t(k)], kNoHitT)) {
                    rayRegion[i] = std::uint32_t(k);
                    ++counts[std::size_t(k)];
                    low[std::size_t(k)] |= dir < 0.0f;
                    high[std::size_t(k)] |= dir > 0.0f;
                    break;
                }
            }
        }
        std::copy(counts.begin(), counts.end(), rayCounts.begin() + std::ptrdiff_t(c * n));
        std::copy(low.begin(), low.end(), chunkLow.begin() + std::ptrdiff_t(c * n));
        std::copy(high.begin(), high.end(), chunkHigh.begin() + std::ptrdiff_t(c * n));
    });

    // Pass 1 for triangles: the range of regions whose widened slab each traced triangle
    // overlaps (i indexes the traced triangles; their ids are g.tracedTriangle(i)).
    const std::size_t traced = g.tracedTriangleCount();
    const std::size_t triChunks = std::max<std::size_t>(1, std::min<std::size_t>(64, traced / 4096 + 1));
    std::vector<std::uint32_t> triCounts(triChunks * n, 0);
    std::vector<std::uint32_t> triFirst(traced), triLast(traced);
    plan.add("triangle region range (binning)", std::uint64_t(traced) * 8);
    auto triChunkRange = [&](std::size_t c) {
        return std::pair<std::size_t, std::size_t>(traced * c / triChunks, traced * (c + 1) / triChunks);
    };
    pool.parallelFor(triChunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = triChunkRange(c);
        std::vector<std::uint32_t> counts(n, 0);
        for (std::size_t i = begin; i < end; ++i) {
            const Bounds& b = tb[g.tracedTriangle(i)];
            const float lo = b.lo[axis], hi = b.hi[axis];
            int first = std::clamp(slabOf(lo, boundary) - 1, 0, int(n) - 1);
            while (first + 1 < int(n) && lo > wideHi[std::size_t(first)][axis]) ++first;
            while (first > 0 && lo <= wideHi[std::size_t(first - 1)][axis]) --first;
            int last = std::clamp(slabOf(hi, boundary) + 1, first, int(n) - 1);
            while (last > first && hi < wideLo[std::size_t(last)][axis]) --last;
            while (last + 1 < int(n) && hi >= wideLo[std::size_t(last + 1)][axis]) ++last;
            triFirst[i] = std::uint32_t(first);
            triLast[i] = std::uint32_t(last);
            for (int k = first; k <= last; ++k) ++counts[std::size_t(k)];
        }
        std::copy(counts.begin(), counts.end(), triCounts.begin() + std::ptrdiff_t(c * n));
    });

    // Offsets: region by region, chunk by chunk, so the fill is deterministic.
    std::vector<std::uint32_t> rayOffset(chunks * n), triOffset(triChunks * n);
    std::uint64_t rayTotal = 0, triTotal = 0;
    for (unsigned k = 0; k < n; ++k) {
        Region& r = d.regions[k];
        r.rayBegin = std::uint32_t(rayTotal);
        for (std::size_t c = 0; c < chunks; ++c) {
            rayOffset[c * n + k] = std::uint32_t(rayTotal);
            rayTotal += rayCounts[c * n + k];
        }
        r.rayEnd = std::uint32_t(rayTotal);
        r.terminated = r.rayBegin;
        r.triBegin = std::uint32_t(triTotal);
        for (std::size_t c = 0; c < triChunks; ++c) {
            triOffset[c * n + k] = std::uint32_t(triTotal);
            triTotal += triCounts[c * n + k];
        }
        r.triEnd = std::uint32_t(triTotal);
        if (triTotal > 0xFFFFFFFFull) throw std::runtime_error("triangle copies exceed 32-bit ids");
    }
    d.raysTowardLow.assign(n, 0);
    d.raysTowardHigh.assign(n, 0);
    for (std::size_t c = 0; c < chunks; ++c)
        for (unsigned k = 0; k < n; ++k) {
            d.raysTowardLow[k] |= chunkLow[c * n + k];
            d.raysTowardHigh[k] |= chunkHigh[c * n + k];
        }
    d.culledRays = rays.size() - rayTotal;
    d.straddlerCopies = triTotal - traced;
    plan.add("binning counters", std::uint64_t(chunks + triChunks) * n * 8 + std::uint64_t(chunks) * n * 2);
    plan.add("region table", std::uint64_t(n) * sizeof(Region));
    plan.add("ray ids", rayTotal * 4);
    plan.add("triangle ids (with straddlers)", triTotal * 4);
    for (const Region& r : d.regions) {
        d.mostRegionRays = std::max<std::uint64_t>(d.mostRegionRays, r.rayEnd - r.rayBegin);
        d.mostRegionTriangles = std::max<std::uint64_t>(d.mostRegionTriangles, r.triEnd - r.triBegin);
    }
    std::uint64_t pairs = 0;
    for (const TransferRound& round : transferSchedule(d)) pairs += round.pairs.size();
    plan.addWork("rays outside the scene box", d.culledRays, "culled before division");
    plan.addWork("regions", n, "sub-scenes along " + std::string(1, "xyz"[axis]));
    plan.addWork("triangle copies in more than one region", d.straddlerCopies);
    plan.addWork("transfer pairs", pairs,
                 "of " + std::to_string(std::uint64_t(n) * (n - 1)) + "; the others have no ray that can reach their triangles");
    if (planTracer) planTracer(d, plan);
    if (onPlan && !onPlan(plan)) return d;

    // Pass 2: fill.
    d.rayIds.resize(rayTotal);
    d.triIds.resize(triTotal);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, rays.size());
        std::vector<std::uint32_t> offset(rayOffset.begin() + std::ptrdiff_t(c * n), rayOffset.begin() + std::ptrdiff_t(c * n + n));
        for (std::size_t i = begin; i < end; ++i)
            if (rayRegion[i] != kCulled) d.rayIds[offset[rayRegion[i]]++] = std::uint32_t(i);
    });
    pool.parallelFor(triChunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = triChunkRange(c);
        std::vector<std::uint32_t> offset(triOffset.begin() + std::ptrdiff_t(c * n), triOffset.begin() + std::ptrdiff_t(c * n + n));
        for (std::size_t i = begin; i < end; ++i)
            for (std::uint32_t k = triFirst[i]; k <= triLast[i]; ++k) d.triIds[offset[k]++] = g.tracedTriangle(i);
    });
    d.complete = true;
    return d;
}

std::vector<TransferRound> transferSchedule(const Division& d, bool raysKnown) {
    const std::uint32_t n = std::uint32_t(d.regions.size());
    auto hasRays = [&](std::uint32_t k) { return !raysKnown || d.regions[k].rayEnd > d.regions[k].rayBegin; };
    auto hasTris = [&](std::uint32_t k) { return d.regions[k].triEnd > d.regions[k].triBegin; };
    std::vector<TransferRound> rounds;
    for (std::uint32_t s = 1; s < n; ++s) {
        TransferRound round{"toward-low " + std::to_string(s), {}};
        for (std::uint32_t i = 0; i + s < n; ++i)
            if ((!raysKnown || d.raysTowardLow[i + s]) && hasRays(i + s) && hasTris(i)) round.pairs.push_back({i + s, i});
        if (!round.pairs.empty()) rounds.push_back(std::move(round));
    }
    for (std::uint32_t s = 1; s < n; ++s) {
        TransferRound round{"toward-high " + std::to_string(s), {}};
        for (std::uint32_t i = s; i < n; ++i)
            if ((!raysKnown || d.raysTowardHigh[i - s]) && hasRays(i - s) && hasTris(i)) round.pairs.push_back({i - s, i});
        if (!round.pairs.empty()) rounds.push_back(std::move(round));
    }
    return rounds;
}

}  // namespace dacrt
