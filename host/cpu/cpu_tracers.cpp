#include "cpu/cpu_tracers.hpp"

#include <algorithm>
#include <atomic>
#include <numeric>

#include "cpu/backend_options.hpp"
#include "cpu/traversal.hpp"
#include "core/errors.hpp"
#include "cpu/scene_division.hpp"
#include "core/timing.hpp"

namespace dacrt {
namespace {

void planFrameInputs(const FrameGeometry& g, MemoryPlan& plan) {
    plan.add("rays", std::uint64_t(g.rays->size()) * sizeof(Ray));
    plan.add("hits", std::uint64_t(g.rays->size()) * sizeof(Hit));
    plan.add("triangles", std::uint64_t(g.triangles->size()) * sizeof(Triangle));
    plan.add("triangle bounds", std::uint64_t(g.triangles->size()) * sizeof(Bounds));
}

// Every ray's best hit starts at its segment's end (missHit).
void startHits(const FrameGeometry& g, std::vector<Hit>& hits) {
    hits.resize(g.rays->size());
    for (std::size_t i = 0; i < hits.size(); ++i) hits[i] = missHit((*g.rays)[i]);
}

Box regionBox(const Region& r) {
    Box b;
    b.lo = r.lo;
    b.hi = r.hi;
    return b;
}

}  // namespace

TraceResult traceBrute(const FrameGeometry& g, ThreadPool& pool, const PlanHook& onPlan, const ProgressHook& onProgress) {
    TraceResult result;
    planFrameInputs(g, result.memory);
    if (onPlan && !onPlan(result.memory)) return result;
    const std::vector<Ray>& rays = *g.rays;
    const std::vector<Triangle>& tris = *g.triangles;
    const std::size_t traced = g.tracedTriangleCount();
    result.hits.resize(rays.size());
    const bool anyHit = g.query == HitQuery::Any;
    const std::size_t blocks = (rays.size() + 63) / 64;
    std::atomic<std::size_t> blocksDone{0};
    pool.parallelFor(blocks, [&](std::size_t block, unsigned) {
        const std::size_t end = std::min(rays.size(), (block + 1) * 64);
        for (std::size_t i = block * 64; i < end; ++i) {
            Hit best = missHit(rays[i]);
            for (std::size_t k = 0; k < traced; ++k) {
                const std::uint32_t p = g.tracedTriangle(k);
                testTriangle(rays[i], tris[p], p, best);
                if (anyHit && best.prim != kMissPrim) break;
            }
            result.hits[i] = best;
        }
        if (onProgress) onProgress(double(++blocksDone) / double(blocks));
    });
    result.counters.rayTriangleTests = std::uint64_t(rays.size()) * traced;
    result.threads = pool.size();
    return result;
}

TraceResult traceSequential(const FrameGeometry& g, const DacrtOptions& options, const PlanHook& onPlan) {
    TraceResult result;
    const std::uint32_t rayCount = std::uint32_t(g.rays->size());
    const std::uint32_t triCount = std::uint32_t(g.tracedTriangleCount());
    planFrameInputs(g, result.memory);
    result.memory.add("ray ids", std::uint64_t(rayCount) * 4);
    result.memory.add("triangle ids", std::uint64_t(triCount) * 4);
    const DacrtOptions resolved = options.resolvedFor(Backend::CpuSeq);
    const std::uint64_t scratchIds = usesSimd(g, resolved) ? partitionScratchIds(rayCount, triCount) : 0;
    if (scratchIds) result.memory.add("partition scratch", scratchIds * 4);
    planPacketBuffers(g, resolved, scratchIds, 1, result.memory);
    if (onPlan && !onPlan(result.memory)) return result;

    startHits(g, result.hits);
    std::vector<std::uint32_t> rayIds(rayCount), triIds(triCount);
    std::iota(rayIds.begin(), rayIds.end(), 0u);
    for (std::uint32_t i = 0; i < triCount; ++i) triIds[i] = g.tracedTriangle(i);
    std::vector<std::uint32_t> scratch(scratchIds);
    PacketStorage packets(g, resolved, scratchIds, 1);
    DacrtTraversal traversal(
        g, options,
        {result.hits.data(), rayIds.data(), triIds.data(), scratchIds ? scratch.data() : nullptr, packets.forWorker(0)},
        result.counters);
    std::uint32_t terminated = 0;
    const std::uint32_t crossing = traversal.trace(g.sceneBox, terminated, rayCount, 0, triCount);
    result.counters.raysCulled = rayCount - crossing;
    result.counters.terminatedStep1 = terminated;
    return result;
}

TraceResult traceParallel(const FrameGeometry& g, const TraceOptions& options, ThreadPool& pool,
                          const PlanHook& onPlan) {
    TraceResult result;
    result.threads = pool.size();
    const unsigned regions = options.regions ? options.regions : pool.size();
    result.regions = regions;
    planFrameInputs(g, result.memory);

    auto start = Clock::now();
    const int axis = options.axis == DivisionAxis::Best ? chooseDivisionAxis(g, regions) : int(options.axis) - 1;
    result.axis = axis;
    const DacrtOptions resolved = options.dacrt.resolvedFor(Backend::Cpu);
    std::uint64_t scratchIds = 0;
    auto planWorkers = [&](const Division& d, MemoryPlan& plan) {
        if (!usesSimd(g, resolved)) return;
        scratchIds = partitionScratchIds(d.mostRegionRays, d.mostRegionTriangles);
        plan.add("partition scratch (per thread)", scratchIds * 4 * pool.size());
        planPacketBuffers(g, resolved, scratchIds, pool.size(), plan);
    };
    Division division = divideScene(g, regions, axis, pool, result.memory, onPlan, planWorkers);
    if (!division.complete) return result;
    startHits(g, result.hits);
    const std::vector<TransferRound> schedule = transferSchedule(division);
    result.phaseMs.emplace_back("divide", msSince(start));
    result.counters.raysCulled = division.culledRays;

    std::vector<Counters> perWorker(pool.size());
    std::vector<std::uint32_t> scratch(scratchIds * pool.size());
    PacketStorage packets(g, resolved, scratchIds, pool.size());
    std::vector<Region>& table = division.regions;
    // Step 1 finishes rays that never leave their slab; a transfer finishes the rays that
    // move toward the triangles' region but cannot reach it (nor, then, any region beyond).
    auto traceItem = [&](std::uint32_t rayRegion, std::uint32_t triRegion, unsigned worker) {
        Region& rays = table[rayRegion];
        const Region& tris = table[triRegion];
        DacrtTraversal traversal(g, options.dacrt,
                                 {result.hits.data(), division.rayIds.data(), division.triIds.data(),
                                  scratchIds ? scratch.data() + worker * scratchIds : nullptr,
                                  packets.forWorker(worker)},
                                 perWorker[worker]);
        const RetireRule retire{axis, triRegion == rayRegion ? 0 : (triRegion > rayRegion ? 1 : -1)};
        traversal.trace(regionBox(tris), rays.terminated, rays.rayEnd, tris.triBegin, tris.triEnd, retire);
    };
    auto terminatedTotal = [&] {
        std::uint64_t t = 0;
        for (const Region& r : table) t += r.terminated - r.rayBegin;
        return t;
    };

    // Step 1: biggest regions first, so the dynamic hand-out ends evenly.
    start = Clock::now();
    std::vector<std::uint32_t> order(regions);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return std::uint64_t(table[a].rayEnd - table[a].rayBegin) * (table[a].triEnd - table[a].triBegin) >
               std::uint64_t(table[b].rayEnd - table[b].rayBegin) * (table[b].triEnd - table[b].triBegin);
    });
    result.step1RegionMs.assign(regions, 0.0);
    pool.parallelFor(regions, [&](std::size_t i, unsigned worker) {
        const auto itemStart = Clock::now();
        traceItem(order[i], order[i], worker);
        result.step1RegionMs[order[i]] = msSince(itemStart);
    });
    result.counters.terminatedStep1 = terminatedTotal();
    result.phaseMs.emplace_back("step1", msSince(start));

    // Transfer rounds, one after another; the pairs of a round in parallel.
    start = Clock::now();
    std::uint64_t before = result.counters.terminatedStep1;
    for (const TransferRound& round : schedule) {
        std::vector<TransferPair> live;
        for (const TransferPair& p : round.pairs)
            if (table[p.rayRegion].terminated < table[p.rayRegion].rayEnd) live.push_back(p);
        result.counters.transferWorkItems += live.size();
        result.counters.transferWorkItemsSkipped += round.pairs.size() - live.size();
        pool.parallelFor(live.size(), [&](std::size_t i, unsigned worker) {
            traceItem(live[i].rayRegion, live[i].triRegion, worker);
        });
        const std::uint64_t now = terminatedTotal();
        result.counters.roundNames.push_back(round.name);
        result.counters.terminatedPerRound.push_back(now - before);
        before = now;
    }
    result.phaseMs.emplace_back("transfer", msSince(start));
    for (const Counters& c : perWorker) result.counters.add(c);
    return result;
}

TraceResult traceCpu(const FrameGeometry& g, const TraceOptions& options, ThreadPool& pool, const PlanHook& onPlan,
                     const ProgressHook& onProgress) {
    checkTraceOptions(options);
    switch (options.backend) {
        case Backend::Brute: return traceBrute(g, pool, onPlan, onProgress);
        case Backend::CpuSeq: return traceSequential(g, options.dacrt, onPlan);
        case Backend::Cpu: {
            const std::uint64_t pairs = std::uint64_t(g.rays->size()) * g.tracedTriangleCount();
            const bool small = g.rays->size() < kSequentialBelowRays && pairs < kSequentialBelowPairs;
            if (options.regions == 0 && options.skips.subScenes && small) {
                const std::vector<WorkLine> line{{"sub-scenes", 0,
                                                  "none: " + std::to_string(g.rays->size()) + " rays and " +
                                                      std::to_string(pairs) +
                                                      " ray-triangle pairs trace faster as one sequential DACRT"}};
                TraceResult r = traceSequential(g, options.dacrt, withWorkLines(onPlan, line, false));
                r.threads = 1;
                r.regions = 1;
                r.memory.work.insert(r.memory.work.end(), line.begin(), line.end());
                return r;
            }
            return traceParallel(g, options, pool, onPlan);
        }
        case Backend::Gpu:
        case Backend::Embree:
        case Backend::RayQuery: break;
    }
    throw InternalError("traceCpu called for the " + toString(options.backend) + " backend");
}

}  // namespace dacrt
