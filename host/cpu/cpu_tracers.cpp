#include "cpu/cpu_tracers.hpp"

#include <algorithm>
#include <atomic>
#include <numeric>
#include <optional>

#include "cpu/backend_options.hpp"
#include "cpu/frame_start.hpp"
#include "cpu/image_bands.hpp"
#include "cpu/traversal.hpp"
#include "core/errors.hpp"
#include "core/mapped_memory.hpp"
#include "cpu/scene_division.hpp"
#include "cpu/subtrees.hpp"
#include "core/timing.hpp"

namespace dacrt {
namespace {

Box regionBox(const Region& r) {
    Box b;
    b.lo = r.lo;
    b.hi = r.hi;
    return b;
}

// Each worker's partition scratch, in ids, from the largest region's counts (0: the scalar
// path runs, without scratch).
std::uint64_t workerScratchIds(const FrameGeometry& g, const DacrtOptions& resolved, const Division& d) {
    return usesSimd(g, resolved) ? partitionScratchIds(d.mostRegionRays, d.mostRegionTriangles) : 0;
}

// The workers' buffers: their partition scratch and packets.
void planWorkers(const FrameGeometry& g, const DacrtOptions& resolved, std::uint64_t scratchIds, unsigned workers,
                 MemoryPlan& plan) {
    if (!usesSimd(g, resolved)) return;
    plan.add("partition scratch (per thread)", scratchIds * 4 * workers);
    planPacketBuffers(g, resolved, scratchIds, workers, plan);
}

// One frame of the parallel scheme, stage by stage: the division (with the plan), Step 1
// over every region, then the transfer rounds. Step 1 finishes the rays that never leave
// their slab; a transfer finishes the rays that move toward the triangles' region but cannot
// reach it (nor, then, any region beyond).
class ParallelFrame {
public:
    ParallelFrame(const FrameGeometry& g, const TraceOptions& options, ThreadPool& pool)
        : g_(g), options_(options), pool_(pool), resolved_(options.dacrt.resolvedFor(Backend::Cpu)) {
        result_.threads = pool.size();
        result_.regions = options.regions ? options.regions : pool.size();
        planFrameInputs(g, result_.memory);
    }

    // False: onPlan stopped the frame at the plan.
    bool divide(const PlanHook& onPlan) {
        const auto start = Clock::now();
        const unsigned regions = result_.regions;
        const int axis = options_.axis == DivisionAxis::Best ? chooseDivisionAxis(g_, regions) : int(options_.axis) - 1;
        result_.axis = axis;
        auto planTracer = [&](const Division& d, MemoryPlan& plan) {
            scratchIds_ = workerScratchIds(g_, resolved_, d);
            planWorkers(g_, resolved_, scratchIds_, pool_.size(), plan);
        };
        division_ = divideScene(g_, regions, axis, pool_, result_.memory, onPlan, planTracer);
        if (!division_.complete) return false;
        raysShareSegment_ = startHits(g_, result_.hits, &pool_);
        schedule_ = transferSchedule(division_);
        result_.phases.divide = msSince(start);
        result_.counters.raysCulled = division_.culledRays;
        perWorker_.resize(pool_.size());
        resizeMapped(scratch_, scratchIds_ * pool_.size());
        packets_.emplace(g_, resolved_, scratchIds_, pool_.size());
        return true;
    }

    // Biggest regions first, so the dynamic hand-out ends evenly.
    void traceStep1() {
        const auto start = Clock::now();
        const std::vector<Region>& table = division_.regions;
        const unsigned regions = result_.regions;
        std::vector<std::uint32_t> order(regions);
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            return std::uint64_t(table[a].rayEnd - table[a].rayBegin) * (table[a].triEnd - table[a].triBegin) >
                   std::uint64_t(table[b].rayEnd - table[b].rayBegin) * (table[b].triEnd - table[b].triBegin);
        });
        result_.step1RegionMs.assign(regions, 0.0);
        pool_.parallelFor(regions, [&](std::size_t i, unsigned worker) {
            const auto itemStart = Clock::now();
            traceItem(order[i], order[i], worker);
            result_.step1RegionMs[order[i]] = msSince(itemStart);
        });
        result_.counters.finishedStep1 = finishedRays();
        result_.phases.step1 = msSince(start);
    }

    // One round after another; the pairs of a round in parallel.
    void traceTransfers() {
        const auto start = Clock::now();
        const std::vector<Region>& table = division_.regions;
        std::uint64_t before = result_.counters.finishedStep1;
        for (const TransferRound& round : schedule_) {
            std::vector<TransferPair> live;
            for (const TransferPair& p : round.pairs)
                if (table[p.rayRegion].terminated < table[p.rayRegion].rayEnd) live.push_back(p);
            result_.counters.transferWorkItems += live.size();
            result_.counters.transferWorkItemsSkipped += round.pairs.size() - live.size();
            pool_.parallelFor(live.size(), [&](std::size_t i, unsigned worker) {
                traceItem(live[i].rayRegion, live[i].triRegion, worker);
            });
            const std::uint64_t now = finishedRays();
            result_.counters.roundNames.push_back(round.name);
            result_.counters.finishedPerRound.push_back(now - before);
            before = now;
        }
        result_.phases.transfer = msSince(start);
        for (const Counters& c : perWorker_) result_.counters.add(c);
    }

    TraceResult finish() { return std::move(result_); }

private:
    // One work item: a region's live rays against a region's triangles, on `worker`'s buffers.
    void traceItem(std::uint32_t rayRegion, std::uint32_t triRegion, unsigned worker) {
        Region& rays = division_.regions[rayRegion];
        const Region& tris = division_.regions[triRegion];
        DacrtTraversal traversal(g_, options_.dacrt,
                                 {result_.hits.data(), division_.rayIds.data(), division_.triIds.data(),
                                  scratchIds_ ? scratch_.data() + worker * scratchIds_ : nullptr,
                                  packets_->forWorker(worker), raysShareSegment_},
                                 perWorker_[worker]);
        const RetireRule retire{result_.axis, triRegion == rayRegion ? 0 : (triRegion > rayRegion ? 1 : -1)};
        traversal.trace(regionBox(tris), rays.terminated, rays.rayEnd, tris.triBegin, tris.triEnd, retire);
    }

    // Rays with their final hit, over every region.
    std::uint64_t finishedRays() const {
        std::uint64_t t = 0;
        for (const Region& r : division_.regions) t += r.terminated - r.rayBegin;
        return t;
    }

    const FrameGeometry& g_;
    const TraceOptions& options_;
    ThreadPool& pool_;
    const DacrtOptions resolved_;
    TraceResult result_;
    Division division_;
    std::vector<TransferRound> schedule_;
    std::uint64_t scratchIds_ = 0;
    bool raysShareSegment_ = false;
    std::vector<Counters> perWorker_;
    std::vector<std::uint32_t> scratch_;
    std::optional<PacketStorage> packets_;
};

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

namespace {

// One sequential DACRT of the rays rayIds[0, rayCount) over the triangles triIds[0, triCount),
// from the scene box down; culled and finished rays counted.
void traceRayIds(const FrameGeometry& g, const DacrtOptions& options, const TraversalBuffers& buffers,
                 std::uint32_t rayCount, std::uint32_t triCount, Counters& counters) {
    DacrtTraversal traversal(g, options, buffers, counters);
    std::uint32_t finished = 0;  // the pivot: rays before it are finished
    const std::uint32_t crossing = traversal.trace(g.sceneBox, finished, rayCount, 0, triCount);
    counters.raysCulled += rayCount - crossing;
    counters.finishedStep1 += finished;
}

}  // namespace

namespace {

// The partition scratch, in ids, of a sequential DACRT of rayCount rays over g's traced
// triangles (0: the scalar path runs, without scratch).
std::uint64_t sequentialScratchIds(const FrameGeometry& g, std::uint64_t rayCount, const DacrtOptions& resolved) {
    return usesSimd(rayCount, g.triangles->size(), resolved) ? partitionScratchIds(rayCount, g.tracedTriangleCount()) : 0;
}

}  // namespace

MemoryPlan sequentialPlan(const FrameGeometry& g, std::uint64_t rayCount, const DacrtOptions& options) {
    MemoryPlan plan;
    planFrameInputs(g, rayCount, plan);
    plan.add("ray ids", rayCount * 4);
    plan.add("triangle ids", std::uint64_t(g.tracedTriangleCount()) * 4);
    const DacrtOptions resolved = options.resolvedFor(Backend::CpuSeq);
    const std::uint64_t scratchIds = sequentialScratchIds(g, rayCount, resolved);
    if (scratchIds) plan.add("partition scratch", scratchIds * 4);
    if (packetTiles(g) > 0) planPacketBuffers(g, resolved, scratchIds, 1, plan);
    return plan;
}

TraceResult traceSequential(const FrameGeometry& g, const DacrtOptions& options, const PlanHook& onPlan) {
    TraceResult result;
    const std::uint32_t rayCount = std::uint32_t(g.rays->size());
    const std::uint32_t triCount = std::uint32_t(g.tracedTriangleCount());
    result.memory = sequentialPlan(g, rayCount, options);
    if (onPlan && !onPlan(result.memory)) return result;
    const DacrtOptions resolved = options.resolvedFor(Backend::CpuSeq);
    const std::uint64_t scratchIds = sequentialScratchIds(g, rayCount, resolved);

    const bool raysShareSegment = startHits(g, result.hits, nullptr);
    std::vector<std::uint32_t> rayIds(rayCount), triIds;
    std::iota(rayIds.begin(), rayIds.end(), 0u);
    fillTracedTriangleIds(g, triIds);
    std::vector<std::uint32_t> scratch(scratchIds);
    PacketStorage packets(g, resolved, scratchIds, 1);
    traceRayIds(g, options,
                {result.hits.data(), rayIds.data(), triIds.data(), scratchIds ? scratch.data() : nullptr,
                 packets.forWorker(0), raysShareSegment},
                rayCount, triCount, result.counters);
    return result;
}

TraceResult traceImageBands(const FrameGeometry& g, const DacrtOptions& options, ThreadPool& pool,
                            const std::vector<std::uint32_t>& bands, const PlanHook& onPlan) {
    TraceResult result;
    const std::uint32_t rayCount = std::uint32_t(g.rays->size());
    const std::uint32_t triCount = std::uint32_t(g.tracedTriangleCount());
    const std::size_t bandCount = bands.size() - 1;
    // Any of the pool's threads may take a band: each has its arrays (a thread that takes
    // none allocates no ids or scratch; the plan counts the threads that can be busy at once).
    const unsigned threads = pool.size();
    const unsigned busy = unsigned(std::min<std::size_t>(threads, bandCount));
    std::uint32_t widest = 0;
    for (std::size_t b = 0; b < bandCount; ++b) widest = std::max(widest, bands[b + 1] - bands[b]);
    const DacrtOptions resolved = options.resolvedFor(Backend::CpuSeq);
    const std::uint64_t scratchIds = usesSimd(g, resolved) ? partitionScratchIds(widest, triCount) : 0;
    planFrameInputs(g, result.memory);
    result.memory.add("ray ids", std::uint64_t(rayCount) * 4);
    // Each band's own triangle ids (bandTriangleIds: at most every traced one a band), and the
    // bands each traced triangle reaches (with each chunk's count and offset a band).
    result.memory.add("triangle ids (per band, at most)", std::uint64_t(triCount) * 4 * bandCount);
    result.memory.add("bands of each triangle", std::uint64_t(triCount) * 8 +
                                                    (triCount / kFrameScanChunk + 1) * bandCount * 12);
    if (scratchIds) result.memory.add("partition scratch (per thread)", scratchIds * 4 * busy);
    planPacketBuffers(g, resolved, scratchIds, threads, result.memory);
    result.memory.work.push_back({"image bands side by side", bandCount,
                                  "rows of 8x8 tiles, each a sequential DACRT on one of " + std::to_string(busy) +
                                      " workers: no division or transfer rounds"});
    if (onPlan && !onPlan(result.memory)) return result;

    const auto start = Clock::now();
    const bool raysShareSegment = startHits(g, result.hits, &pool);
    std::vector<std::uint32_t> rayIds(rayCount);
    std::iota(rayIds.begin(), rayIds.end(), 0u);
    // The traversal permutes its band's ids.
    std::vector<std::vector<std::uint32_t>> triIds = bandTriangleIds(g, bands, pool), scratch(threads);
    PacketStorage packets(g, resolved, scratchIds, threads);
    std::vector<Counters> counters(threads);
    pool.parallelFor(bandCount, [&](std::size_t b, unsigned w) {
        scratch[w].resize(scratchIds);
        traceRayIds(g, options,
                    {result.hits.data(), rayIds.data() + bands[b], triIds[b].data(),
                     scratchIds ? scratch[w].data() : nullptr, packets.forWorker(w), raysShareSegment},
                    bands[b + 1] - bands[b], std::uint32_t(triIds[b].size()), counters[w]);
    });
    for (const Counters& c : counters) {
        result.counters.add(c);
        result.counters.raysCulled += c.raysCulled;
        result.counters.finishedStep1 += c.finishedStep1;
    }
    result.phases.step1 = msSince(start);
    result.threads = busy;
    result.regions = 1;
    return result;
}

TraceResult traceParallel(const FrameGeometry& g, const TraceOptions& options, ThreadPool& pool,
                          const PlanHook& onPlan) {
    ParallelFrame frame(g, options, pool);
    if (frame.divide(onPlan)) {
        frame.traceStep1();
        frame.traceTransfers();
    }
    return frame.finish();
}

namespace {

// Whether the cpu backend traces a frame as one sequential DACRT, too small to pay for more.
bool sequentialForItsSize(std::uint64_t rays, std::uint64_t tracedTriangles, const TraceOptions& options) {
    const bool small = rays < kSequentialBelowRays && rays * tracedTriangles < kSequentialBelowPairs;
    return options.regions == 0 && options.skips.subScenes && small;
}

}  // namespace

bool cpuTracesAsSubtrees(std::uint64_t rays, std::uint64_t tracedTriangles, HitQuery query, const TraceOptions& options,
                         unsigned workers) {
    return options.backend == Backend::Cpu && options.regions == 0 && options.skips.subScenes &&
           !sequentialForItsSize(rays, tracedTriangles, options) &&
           tracesAsSubtrees(rays, tracedTriangles, query, options.dacrt, workers);
}

TraceResult traceCpu(const FrameGeometry& g, const TraceOptions& options, ThreadPool& pool, const PlanHook& onPlan,
                     const ProgressHook& onProgress) {
    checkTraceOptions(options);
    switch (options.backend) {
        case Backend::Brute: return traceBrute(g, pool, onPlan, onProgress);
        case Backend::CpuSeq: return traceSequential(g, options.dacrt, onPlan);
        case Backend::Cpu: {
            if (sequentialForItsSize(g.rays->size(), g.tracedTriangleCount(), options)) {
                const std::uint64_t pairs = std::uint64_t(g.rays->size()) * g.tracedTriangleCount();
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
            // Subtrees and bands skip the sub-scenes too: --no-skip subscenes asks for the
            // parallel scheme.
            if (options.regions == 0 && options.skips.subScenes) {
                if (cpuTracesAsSubtrees(g.rays->size(), g.tracedTriangleCount(), g.query, options, pool.size()) &&
                    tracesAsSubtrees(g, options.dacrt, pool.size()))
                    return traceSubtrees(g, options.dacrt, pool, onPlan);
                const std::vector<std::uint32_t> bands = imageBands(g, pool.size());
                if (!bands.empty()) return traceImageBands(g, options.dacrt, pool, bands, onPlan);
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
