#include "cpu/subtrees.hpp"

#include <algorithm>
#include <functional>
#include <memory>
#include <numeric>
#include <string>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "cpu/frame_start.hpp"
#include "cpu/traversal.hpp"

namespace dacrt {
namespace {

const char* const kSubtreesLine = "subtrees side by side";

// Ids per chunk of a split's filters on the pool.
constexpr std::size_t kFilterChunk = 65536;

// A node of the upper levels: its box, its place in the recursion, and its live rays and
// triangles, filtered from its parent's as a sequential DACRT filters them.
struct Subtree {
    Box box;
    std::uint32_t depth = 0;
    std::uint32_t stalls = 0;
    bool leaf = false;  // the leaf rules end it here: it is traced whole
    std::vector<std::uint32_t> rayIds, triIds;
    // Once traced: the hits of the rays it ended, which its traversal moved to rayIds' front.
    std::vector<Hit> hits;
    std::uint64_t cost() const { return std::uint64_t(rayIds.size()) + triIds.size(); }
};

// Stable partition of ids[0, count) with scratch for count + kScratchSlack ids: how many it keeps.
using IdPartition = std::function<std::uint32_t(std::uint32_t* ids, std::uint32_t count, std::uint32_t* scratch)>;

// One filter of a split: the ids of `from` that `keep` keeps, in their order, into `into`.
struct IdFilter {
    const std::vector<std::uint32_t>* from;
    IdPartition keep;
    std::vector<std::uint32_t>* into;
};

// The filters run together on the pool: each source copied and partitioned chunk by chunk,
// side by side, then each chunk's kept ids gathered after the earlier chunks'.
void runFilters(const std::vector<IdFilter>& filters, ThreadPool& pool, std::vector<std::vector<std::uint32_t>>& scratch) {
    struct Chunk {
        std::size_t filter, begin, end, kept = 0, offset = 0;
    };
    std::vector<Chunk> chunks;
    std::vector<std::vector<std::uint32_t>> staged(filters.size());
    for (std::size_t f = 0; f < filters.size(); ++f) {
        const std::size_t n = filters[f].from->size();
        staged[f].resize(n);
        for (std::size_t begin = 0; begin < n; begin += kFilterChunk)
            chunks.push_back({f, begin, std::min(n, begin + kFilterChunk)});
    }
    pool.parallelFor(chunks.size(), [&](std::size_t c, unsigned worker) {
        Chunk& chunk = chunks[c];
        const std::vector<std::uint32_t>& from = *filters[chunk.filter].from;
        std::uint32_t* ids = staged[chunk.filter].data() + chunk.begin;
        std::copy(from.begin() + std::ptrdiff_t(chunk.begin), from.begin() + std::ptrdiff_t(chunk.end), ids);
        chunk.kept = filters[chunk.filter].keep(ids, std::uint32_t(chunk.end - chunk.begin), scratch[worker].data());
    });
    std::vector<std::size_t> total(filters.size(), 0);
    for (Chunk& chunk : chunks) {
        chunk.offset = total[chunk.filter];
        total[chunk.filter] += chunk.kept;
    }
    for (std::size_t f = 0; f < filters.size(); ++f) filters[f].into->resize(total[f]);
    pool.parallelFor(chunks.size(), [&](std::size_t c, unsigned) {
        const Chunk& chunk = chunks[c];
        const std::uint32_t* kept = staged[chunk.filter].data() + chunk.begin;
        std::copy(kept, kept + chunk.kept, filters[chunk.filter].into->data() + chunk.offset);
    });
}

// What the upper levels read of the frame.
struct UpperLevels {
    const FrameGeometry& g;
    const DacrtOptions& options;  // resolved
    const Hit* startHits;         // every ray's missHit (the ray filter does not read them)
    simd::SharedRayFields sharedRayFields;
    mutable std::uint64_t rayBoxTests = 0;  // the ray filters' tests (Counters::rayBoxTests)

    // The rays of the (widened) cell among `ids`, as DacrtTraversal::filterRays keeps them.
    IdPartition raysCrossing(const Box& cell) const {
        return [this, cell](std::uint32_t* ids, std::uint32_t count, std::uint32_t* scratch) {
            return simd::partitionRaysMayCrossCell(g.rays->data(), startHits, ids, count, cell, sharedRayFields, scratch);
        };
    }

    // The triangles reaching into a child's cell, as DacrtTraversal::filterTriangles keeps them.
    IdPartition trianglesReaching(const Box& cell, int axis, bool lowChild) const {
        return [this, cell, axis, lowChild](std::uint32_t* ids, std::uint32_t count, std::uint32_t* scratch) {
            return simd::partitionTrianglesOnFace(g.triangleFaces(), ids, count, axis, lowChild,
                                                  lowChild ? cell.hi[axis] : cell.lo[axis], scratch);
        };
    }

    // The node's children, in the order its rays visit them (splitNode's), each with the rays
    // and triangles filtered from the node's; children without either are left out, as the
    // recursion leaves them. False, and the node marked a leaf, where the leaf rules end it.
    bool split(Subtree& node, ThreadPool& pool, std::vector<std::vector<std::uint32_t>>& scratch,
               std::vector<Subtree>& children) const {
        const int axis = longestAxis(node.box);
        const float position = spatialMedian(node.box, axis);
        if (endsAsLeaf(node.box, axis, position, node.rayIds.size() < options.rayLimit,
                       std::uint32_t(node.triIds.size()), node.depth, node.stalls, options)) {
            node.leaf = true;
            return false;
        }
        Box low = node.box, high = node.box;
        low.hi[axis] = position;
        high.lo[axis] = position;
        const bool lowFirst = lowChildFirst(g.order, g.nearSide, axis, position);
        children.assign(2, Subtree{});
        std::vector<IdFilter> filters;
        for (int c = 0; c < 2; ++c) {
            const bool lowChild = (c == 0) == lowFirst;
            const Box cell = widenedBox(lowChild ? low : high, g.margin);
            children[c].box = lowChild ? low : high;
            filters.push_back({&node.rayIds, raysCrossing(cell), &children[c].rayIds});
            filters.push_back({&node.triIds, trianglesReaching(cell, axis, lowChild), &children[c].triIds});
        }
        runFilters(filters, pool, scratch);
        rayBoxTests += 2 * node.rayIds.size();
        for (Subtree& child : children) {
            const bool stalled = child.rayIds.size() == node.rayIds.size() && child.triIds.size() == node.triIds.size();
            child.depth = node.depth + 1;
            child.stalls = stalled ? node.stalls + 1 : 0;
        }
        children.erase(std::remove_if(children.begin(), children.end(),
                                      [](const Subtree& s) { return s.rayIds.empty() || s.triIds.empty(); }),
                       children.end());
        return true;
    }

    // The root (the scene box, the rays crossing it, every traced triangle), split where its
    // subtrees cost most until there are `count` of them or none splits: in the order the
    // recursion visits them.
    // crossing: how many rays cross the scene box.
    std::vector<Subtree> divide(std::size_t count, ThreadPool& pool, std::vector<std::vector<std::uint32_t>>& scratch,
                                std::uint64_t& crossing) const {
        Subtree root;
        root.box = g.sceneBox;
        {  // freed before the splits (planSubtrees counts it as one of the staged copies)
            std::vector<std::uint32_t> every(g.rays->size());
            std::iota(every.begin(), every.end(), 0u);
            runFilters({{&every, raysCrossing(widenedBox(g.sceneBox, g.margin)), &root.rayIds}}, pool, scratch);
            rayBoxTests += every.size();
        }
        crossing = root.rayIds.size();
        fillTracedTriangleIds(g, root.triIds, &pool);
        std::vector<Subtree> subtrees;
        if (!root.rayIds.empty() && !root.triIds.empty()) subtrees.push_back(std::move(root));
        std::vector<Subtree> children;
        while (subtrees.size() < count) {
            std::size_t costliest = subtrees.size();
            for (std::size_t i = 0; i < subtrees.size(); ++i)
                if (!subtrees[i].leaf && (costliest == subtrees.size() || subtrees[i].cost() > subtrees[costliest].cost()))
                    costliest = i;
            if (costliest == subtrees.size()) break;
            if (!split(subtrees[costliest], pool, scratch, children)) continue;
            const auto at = subtrees.erase(subtrees.begin() + std::ptrdiff_t(costliest));
            subtrees.insert(at, std::make_move_iterator(children.begin()), std::make_move_iterator(children.end()));
        }
        return subtrees;
    }
};

void planSubtrees(const FrameGeometry& g, std::size_t count, unsigned workers, std::uint64_t scratchIds, MemoryPlan& plan) {
    const std::uint64_t rays = g.rays->size(), triangles = g.tracedTriangleCount();
    planFrameInputs(g, plan);
    // At any time: the subtrees (one more while a split replaces its node), and the filters'
    // staged copies of the node's ids.
    plan.add("ray and triangle ids of the subtrees (at most)", (count + 3) * (rays + triangles) * 4);
    plan.add("hits of the rays each subtree ends (at most)", count * rays * sizeof(Hit));
    plan.add("hits (per thread)", rays * sizeof(Hit) * workers);
    plan.add("partition scratch (per thread)", scratchIds * 4 * workers);
    plan.work.push_back({kSubtreesLine, count,
                         "the upper levels of one DACRT divided once, each subtree then a sequential DACRT on one of " +
                             std::to_string(workers) + " workers"});
}

}  // namespace

bool tracesAsSubtrees(std::uint64_t rays, std::uint64_t triangles, HitQuery query, const DacrtOptions& options,
                      unsigned workers) {
    // usesSimd's rule from the counts (any-hit rays have no shared start, so no packets).
    return workers > 1 && query == HitQuery::Any && triangles > rays && options.exactDefaults() &&
           rays <= simd::kMaxRays && triangles <= simd::kMaxTriangles && options.split == SplitMethod::SpatialMedian &&
           options.splitCost == SplitCost::Limits;
}

bool tracesAsSubtrees(const FrameGeometry& g, const DacrtOptions& options, unsigned workers) {
    const DacrtOptions resolved = options.resolvedFor(Backend::Cpu);
    return tracesAsSubtrees(g.rays->size(), g.tracedTriangleCount(), g.query, options, workers) &&
           usesSimd(g, resolved) && !usesPackets(g, resolved);
}

TraceResult traceSubtrees(const FrameGeometry& g, const DacrtOptions& options, ThreadPool& pool, const PlanHook& onPlan) {
    const unsigned workers = pool.size();
    if (!tracesAsSubtrees(g, options, workers)) throw InternalError("traceSubtrees called for a frame it does not take");
    const DacrtOptions resolved = options.resolvedFor(Backend::Cpu);
    const std::size_t count = std::size_t(kSubtreesPerWorker) * workers;
    const std::uint64_t scratchIds =
        std::max<std::uint64_t>(partitionScratchIds(g.rays->size(), g.tracedTriangleCount()), kFilterChunk + simd::kScratchSlack);
    TraceResult result;
    planSubtrees(g, count, workers, scratchIds, result.memory);
    if (onPlan && !onPlan(result.memory)) return result;

    const auto start = Clock::now();
    const bool raysShareSegment = startHits(g, result.hits, &pool);
    std::vector<std::vector<std::uint32_t>> scratch(workers, std::vector<std::uint32_t>(scratchIds));
    const UpperLevels upper{g, resolved, result.hits.data(),
                            raysShareSegment ? simd::SharedRayFields::Segment : simd::SharedRayFields::OwnSegment};
    std::uint64_t crossing = 0;
    std::vector<Subtree> subtrees = upper.divide(count, pool, scratch, crossing);
    result.phases.divide = msSince(start);
    // The plan named the most there may be; the result names how many the division made.
    for (WorkLine& line : result.memory.work)
        if (line.name == kSubtreesLine) line.count = subtrees.size();

    // Costliest first, so that the dynamic hand-out ends evenly.
    std::vector<std::size_t> order(subtrees.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return subtrees[a].cost() > subtrees[b].cost(); });
    // Each worker's hits, one per ray of the frame: a subtree starts those of its rays, and
    // only those are read (new Hit[]: no pass over the rest).
    std::vector<std::unique_ptr<Hit[]>> workerHits(workers);
    std::vector<Counters> counters(workers);
    const auto traceStart = Clock::now();
    pool.parallelForRethrowing(order.size(), [&](std::size_t i, unsigned worker) {
        Subtree& s = subtrees[order[i]];
        if (!workerHits[worker]) workerHits[worker].reset(new Hit[g.rays->size()]);
        Hit* hits = workerHits[worker].get();
        for (const std::uint32_t id : s.rayIds) hits[id] = result.hits[id];
        DacrtTraversal traversal(g, options, {hits, s.rayIds.data(), s.triIds.data(), scratch[worker].data(), {}, raysShareSegment},
                                 counters[worker]);
        std::uint32_t ended = 0;
        traversal.traceBelow(s.box, ended, std::uint32_t(s.rayIds.size()), 0, std::uint32_t(s.triIds.size()), s.depth,
                             s.stalls);
        s.hits.resize(ended);
        for (std::uint32_t k = 0; k < ended; ++k) s.hits[k] = hits[s.rayIds[k]];
    });

    // In the order the recursion visits the subtrees: a ray's first hit there is its hit.
    std::uint64_t ended = 0;
    for (const Subtree& s : subtrees) {
        for (std::size_t k = 0; k < s.hits.size(); ++k) {
            Hit& hit = result.hits[s.rayIds[k]];
            if (hit.prim != kMissPrim) continue;
            hit = s.hits[k];
            ++ended;
        }
    }
    result.phases.step1 = msSince(traceStart);
    for (const Counters& c : counters) result.counters.add(c);
    result.counters.rayBoxTests += upper.rayBoxTests;
    result.counters.finishedStep1 = ended;
    result.counters.raysCulled = g.rays->size() - crossing;
    result.threads = workers;
    result.regions = 1;
    return result;
}

}  // namespace dacrt
