#include "cpu/predicates.hpp"
#include "cpu/scene_division.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/mapped_memory.hpp"
#include "cpu/simd_kernels.hpp"

namespace dacrt {
namespace {

constexpr std::uint32_t kCulled = simd::kNoRegion;

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
    return int(simd::slabOf(x, boundary.data(), std::uint32_t(boundary.size() - 1)));
}

// The regions (equal slabs along the axis) and their boxes widened by the margin.
struct Slabs {
    std::vector<float> boundary;
    std::vector<glm::vec3> wideLo, wideHi;  // the widened region boxes the filters use
    glm::vec3 sceneLo, sceneHi;             // the scene box widened
};

Slabs slabRegions(const Box& box, int axis, unsigned n, float m, Division& d) {
    Slabs s{slabBoundaries(box, axis, n), std::vector<glm::vec3>(n), std::vector<glm::vec3>(n),
            box.lo - glm::vec3(m), box.hi + glm::vec3(m)};
    d.regions.resize(n);
    for (unsigned k = 0; k < n; ++k) {
        Region& r = d.regions[k];
        r = Region{};
        r.lo = box.lo;
        r.hi = box.hi;
        r.lo[axis] = s.boundary[k];
        r.hi[axis] = s.boundary[k + 1];
        s.wideLo[k] = r.lo - glm::vec3(m);
        s.wideHi[k] = r.hi + glm::vec3(m);
    }
    return s;
}

// Items are binned in up to 64 chunks of at least 4096, counted chunk by chunk so that the
// fill is deterministic.
std::size_t chunksFor(std::size_t items) { return std::max<std::size_t>(1, std::min<std::size_t>(64, items / 4096 + 1)); }

std::pair<std::size_t, std::size_t> chunkRange(std::size_t c, std::size_t total, std::size_t chunks) {
    return {total * c / chunks, total * (c + 1) / chunks};
}

// Pass 1 for rays: which region each ray meets first (kCulled: none), counted per chunk and
// region, with the directions rays leave each region in.
struct RayBins {
    std::size_t chunks = 1;
    std::vector<std::uint32_t> region;
    std::vector<std::uint32_t> counts;       // chunk c, region k at c * n + k
    std::vector<std::uint8_t> low, high;     // a ray travels toward lower / higher regions
};

RayBins binRays(const FrameGeometry& g, const Slabs& s, int axis, ThreadPool& pool) {
    const std::vector<Ray>& rays = *g.rays;
    const std::size_t n = s.wideLo.size();
    const simd::RegionSlabs slabs{.axis = axis,
                                  .count = std::uint32_t(n),
                                  .boundary = s.boundary.data(),
                                  .wideLo = s.wideLo.data(),
                                  .wideHi = s.wideHi.data(),
                                  .sceneLo = s.sceneLo,
                                  .sceneHi = s.sceneHi};
    RayBins bins;
    bins.chunks = chunksFor(rays.size());
    resizeMapped(bins.region, rays.size());
    bins.counts.assign(bins.chunks * n, 0);
    bins.low.assign(bins.chunks * n, 0);
    bins.high.assign(bins.chunks * n, 0);
    pool.parallelFor(bins.chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, rays.size(), bins.chunks);
        simd::firstRegionsOfRays(rays.data() + begin, end - begin, slabs, bins.region.data() + begin);
        // Counted locally: neighbouring chunks' counters share cache lines.
        std::vector<std::uint32_t> counts(n, 0);
        std::vector<std::uint8_t> low(n, 0), high(n, 0);
        for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t k = bins.region[i];
            if (k == kCulled) continue;
            const float dir = rays[i].dir[axis];
            ++counts[k];
            low[k] |= dir < 0.0f;
            high[k] |= dir > 0.0f;
        }
        std::copy(counts.begin(), counts.end(), bins.counts.begin() + std::ptrdiff_t(c * n));
        std::copy(low.begin(), low.end(), bins.low.begin() + std::ptrdiff_t(c * n));
        std::copy(high.begin(), high.end(), bins.high.begin() + std::ptrdiff_t(c * n));
    });
    return bins;
}

// Pass 1 for triangles: the range of regions whose widened slab each traced triangle
// overlaps (i indexes the traced triangles; their ids are g.tracedTriangle(i)).
struct TriangleBins {
    std::size_t chunks = 1;
    std::vector<std::uint32_t> counts;       // chunk c, region k at c * n + k
    std::vector<std::uint32_t> first, last;  // per traced triangle
};

TriangleBins binTriangles(const FrameGeometry& g, const Slabs& s, int axis, ThreadPool& pool) {
    const std::vector<Bounds>& tb = *g.triangleBounds;
    const std::size_t n = s.wideLo.size();
    const std::size_t traced = g.tracedTriangleCount();
    TriangleBins bins;
    bins.chunks = chunksFor(traced);
    bins.counts.assign(bins.chunks * n, 0);
    resizeMapped(bins.first, traced);
    resizeMapped(bins.last, traced);
    pool.parallelFor(bins.chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, traced, bins.chunks);
        std::vector<std::uint32_t> counts(n, 0);
        for (std::size_t i = begin; i < end; ++i) {
            const Bounds& b = tb[g.tracedTriangle(i)];
            const float lo = b.lo[axis], hi = b.hi[axis];
            int first = std::clamp(slabOf(lo, s.boundary) - 1, 0, int(n) - 1);
            while (first + 1 < int(n) && lo > s.wideHi[std::size_t(first)][axis]) ++first;
            while (first > 0 && lo <= s.wideHi[std::size_t(first - 1)][axis]) --first;
            int last = std::clamp(slabOf(hi, s.boundary) + 1, first, int(n) - 1);
            while (last > first && hi < s.wideLo[std::size_t(last)][axis]) --last;
            while (last + 1 < int(n) && hi >= s.wideLo[std::size_t(last + 1)][axis]) ++last;
            bins.first[i] = std::uint32_t(first);
            bins.last[i] = std::uint32_t(last);
            for (int k = first; k <= last; ++k) ++counts[std::size_t(k)];
        }
        std::copy(counts.begin(), counts.end(), bins.counts.begin() + std::ptrdiff_t(c * n));
    });
    return bins;
}

// Where each chunk's rays and triangles go in the id arrays of each region.
struct Offsets {
    std::vector<std::uint32_t> ray, tri;  // chunk c, region k at c * n + k
    std::uint64_t rayTotal = 0, triTotal = 0;
};

// Offsets region by region, chunk by chunk; the regions' ranges, their largest counts and
// the directions their rays leave in.
Offsets placeRegions(Division& d, const RayBins& rays, const TriangleBins& triangles) {
    const std::size_t n = d.regions.size();
    Offsets o{std::vector<std::uint32_t>(rays.chunks * n), std::vector<std::uint32_t>(triangles.chunks * n)};
    for (std::size_t k = 0; k < n; ++k) {
        Region& r = d.regions[k];
        r.rayBegin = std::uint32_t(o.rayTotal);
        for (std::size_t c = 0; c < rays.chunks; ++c) {
            o.ray[c * n + k] = std::uint32_t(o.rayTotal);
            o.rayTotal += rays.counts[c * n + k];
        }
        r.rayEnd = std::uint32_t(o.rayTotal);
        r.terminated = r.rayBegin;
        r.triBegin = std::uint32_t(o.triTotal);
        for (std::size_t c = 0; c < triangles.chunks; ++c) {
            o.tri[c * n + k] = std::uint32_t(o.triTotal);
            o.triTotal += triangles.counts[c * n + k];
        }
        r.triEnd = std::uint32_t(o.triTotal);
        if (o.triTotal > 0xFFFFFFFFull) throw std::runtime_error("triangle copies exceed 32-bit ids");
    }
    d.raysTowardLow.assign(n, 0);
    d.raysTowardHigh.assign(n, 0);
    for (std::size_t c = 0; c < rays.chunks; ++c)
        for (std::size_t k = 0; k < n; ++k) {
            d.raysTowardLow[k] |= rays.low[c * n + k];
            d.raysTowardHigh[k] |= rays.high[c * n + k];
        }
    for (const Region& r : d.regions) {
        d.mostRegionRays = std::max<std::uint64_t>(d.mostRegionRays, r.rayEnd - r.rayBegin);
        d.mostRegionTriangles = std::max<std::uint64_t>(d.mostRegionTriangles, r.triEnd - r.triBegin);
    }
    return o;
}

// Pass 2: the id arrays filled, each chunk from its offsets.
void fillIds(const FrameGeometry& g, const RayBins& rays, const TriangleBins& triangles, const Offsets& o,
             ThreadPool& pool, Division& d) {
    const std::size_t n = d.regions.size();
    resizeMapped(d.rayIds, o.rayTotal);
    resizeMapped(d.triIds, o.triTotal);
    pool.parallelFor(rays.chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, rays.region.size(), rays.chunks);
        std::vector<std::uint32_t> offset(o.ray.begin() + std::ptrdiff_t(c * n), o.ray.begin() + std::ptrdiff_t(c * n + n));
        for (std::size_t i = begin; i < end; ++i)
            if (rays.region[i] != kCulled) d.rayIds[offset[rays.region[i]]++] = std::uint32_t(i);
    });
    pool.parallelFor(triangles.chunks, [&](std::size_t c, unsigned) {
        const auto [begin, end] = chunkRange(c, triangles.first.size(), triangles.chunks);
        std::vector<std::uint32_t> offset(o.tri.begin() + std::ptrdiff_t(c * n), o.tri.begin() + std::ptrdiff_t(c * n + n));
        for (std::size_t i = begin; i < end; ++i)
            for (std::uint32_t k = triangles.first[i]; k <= triangles.last[i]; ++k) d.triIds[offset[k]++] = g.tracedTriangle(i);
    });
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
    Division d;
    d.axis = axis;
    const Slabs slabs = slabRegions(g.sceneBox, axis, n, g.margin, d);
    const RayBins rays = binRays(g, slabs, axis, pool);
    const TriangleBins triangles = binTriangles(g, slabs, axis, pool);
    Offsets offsets = placeRegions(d, rays, triangles);
    d.culledRays = g.rays->size() - offsets.rayTotal;
    d.straddlerCopies = offsets.triTotal - triangles.first.size();
    std::uint64_t pairs = 0;
    for (const TransferRound& round : transferSchedule(d)) pairs += round.pairs.size();
    plan.append(planDivision(DivisionCounts{.rays = g.rays->size(),
                                            .tracedTriangles = triangles.first.size(),
                                            .rayChunks = rays.chunks,
                                            .triangleChunks = triangles.chunks,
                                            .regions = n,
                                            .axis = axis,
                                            .rayIds = offsets.rayTotal,
                                            .triangleIds = offsets.triTotal,
                                            .culledRays = d.culledRays,
                                            .straddlerCopies = d.straddlerCopies,
                                            .transferPairs = pairs}));
    if (planTracer) planTracer(d, plan);
    if (onPlan && !onPlan(plan)) return d;
    fillIds(g, rays, triangles, offsets, pool, d);
    d.complete = true;
    return d;
}

MemoryPlan planDivision(const DivisionCounts& c) {
    MemoryPlan plan;
    const std::uint64_t n = c.regions;
    plan.add("ray region (binning)", c.rays * 4);
    plan.add("triangle region range (binning)", c.tracedTriangles * 8);
    plan.add("binning counters", std::uint64_t(c.rayChunks + c.triangleChunks) * n * 8 + std::uint64_t(c.rayChunks) * n * 2);
    plan.add("region table", n * sizeof(Region));
    plan.add("ray ids", c.rayIds * 4);
    plan.add("triangle ids (with straddlers)", c.triangleIds * 4);
    plan.addWork("rays outside the scene box", c.culledRays, "culled before division");
    plan.addWork("regions", n, "sub-scenes along " + std::string(1, "xyz"[c.axis]));
    plan.addWork("triangle copies in more than one region", c.straddlerCopies);
    plan.addWork("transfer pairs", c.transferPairs,
                 "of " + std::to_string(n * (n - 1)) + "; the others have no ray that can reach their triangles");
    return plan;
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
