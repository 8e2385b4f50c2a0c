#include "library/triangle_batches.hpp"

#include <algorithm>
#include <optional>
#include <string>

#include "core/errors.hpp"
#include "gpu/binding_set.hpp"

namespace dacrt {
namespace {

std::vector<std::uint32_t> tracedIds(const FrameGeometry& g) {
    if (g.tracedTriangles) return *g.tracedTriangles;
    std::vector<std::uint32_t> ids(g.triangles->size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = std::uint32_t(i);
    return ids;
}

// Whether `a` answers the ray before `b` under the tie rule of every backend.
bool before(const Hit& a, const Hit& b) { return a.t < b.t || (a.t == b.t && a.prim < b.prim); }

void mergeGpuReports(GpuReport& into, const GpuReport& batch) {
    into.dispatchMs.insert(into.dispatchMs.end(), batch.dispatchMs.begin(), batch.dispatchMs.end());
    into.dispatches += batch.dispatches;
    into.workItemsRun += batch.workItemsRun;
    into.workItemsEmpty += batch.workItemsEmpty;
    into.slices += batch.slices;
    into.raysFinished += batch.raysFinished;
    into.validationErrors = std::max(into.validationErrors, batch.validationErrors);  // the device's running count
    into.workPasses.insert(into.workPasses.end(), batch.workPasses.begin(), batch.workPasses.end());
    into.workCost += batch.workCost;
    into.longestChainCost += batch.longestChainCost;  // the batches run one after another
    into.stageTicks.resize(std::max(into.stageTicks.size(), batch.stageTicks.size()), 0);
    for (std::size_t k = 0; k < batch.stageTicks.size(); ++k) into.stageTicks[k] += batch.stageTicks[k];
}

// What a batch exceeded (the frame, for the first batches).
struct Excess {
    std::string limitName;
    std::uint64_t needed = 0;
};

// The batch traced; where it still exceeds a limit of the device, its halves, merged. A batch
// that needs nearly what the larger one it came from needed of the same limit is held back by
// its rays, which no split of the triangles shrinks: refused then.
TraceResult traceSplitting(const FrameGeometry& frame, std::vector<std::uint32_t> ids, const BatchTrace& traceOne,
                           const Excess& larger, const std::vector<WorkLine>& planLines, std::size_t& batches) {
    Excess excess;
    {
        const TriangleBatch batch(frame, ids);
        try {
            TraceResult r = traceOne(batch.geometry, planLines);
            batch.toFrameIds(r.hits);
            ++batches;
            return r;
        } catch (const gpu::DeviceLimitExceeded& e) {
            const bool shrank = e.limitName != larger.limitName || e.needed / 10 * 9 < larger.needed / 10 * 8;
            if (ids.size() < 2 || !shrank) throw;
            excess = {e.limitName, e.needed};
        }
    }
    std::vector<std::vector<std::uint32_t>> halves = splitIds(ids, 2);
    ids = {};
    TraceResult r = traceSplitting(frame, std::move(halves[0]), traceOne, excess, planLines, batches);
    if (r.hits.size() != frame.rays->size()) return r;  // stopped at its plan
    mergeBatch(r, traceSplitting(frame, std::move(halves[1]), traceOne, excess, planLines, batches), frame.query);
    return r;
}

}  // namespace

TriangleBatch::TriangleBatch(const FrameGeometry& frame, std::vector<std::uint32_t> batchIds) : ids(std::move(batchIds)) {
    triangles.reserve(ids.size());
    bounds.reserve(ids.size());
    Box box;
    for (std::uint32_t id : ids) {
        triangles.push_back((*frame.triangles)[id]);
        const Bounds& b = (*frame.triangleBounds)[id];
        bounds.push_back(b);
        box.extend(b.lo);
        box.extend(b.hi);
    }
    geometry = frame;
    geometry.triangles = &triangles;
    geometry.triangleBounds = &bounds;
    geometry.boundsColumns = nullptr;  // the frame's columns hold every triangle, not the batch's
    geometry.tracedTriangles = nullptr;
    geometry.sceneBox = box;
    geometry.margin = filterMargin(box, frame.farthestOrigin);
    geometry.trianglesVersion = 0;
    geometry.sceneId = 0;
}

void TriangleBatch::toFrameIds(std::vector<Hit>& hits) const {
    for (Hit& h : hits)
        if (h.prim < ids.size()) h.prim = ids[h.prim];
}

std::vector<std::vector<std::uint32_t>> splitIds(const std::vector<std::uint32_t>& ids, std::size_t parts) {
    parts = std::max<std::size_t>(1, std::min(parts, ids.size()));
    std::vector<std::vector<std::uint32_t>> out(parts);
    for (std::size_t p = 0; p < parts; ++p)
        out[p].assign(ids.begin() + std::ptrdiff_t(ids.size() * p / parts),
                      ids.begin() + std::ptrdiff_t(ids.size() * (p + 1) / parts));
    return out;
}

void mergeBatch(TraceResult& into, const TraceResult& batch, HitQuery query) {
    if (into.hits.size() != batch.hits.size())
        throw InternalError("triangle batches answered " + std::to_string(into.hits.size()) + " and " +
                            std::to_string(batch.hits.size()) + " rays");
    for (std::size_t i = 0; i < into.hits.size(); ++i) {
        const Hit& b = batch.hits[i];
        const bool take = query == HitQuery::Any ? into.hits[i].prim == kMissPrim && b.prim != kMissPrim
                                                 : before(b, into.hits[i]);
        if (take) into.hits[i] = b;
    }
    into.counters.add(batch.counters);
    into.counters.raysCulled = std::min(into.counters.raysCulled, batch.counters.raysCulled);
    into.phases.add(batch.phases);
    if (into.gpu && batch.gpu) mergeGpuReports(*into.gpu, *batch.gpu);
}

TraceResult traceInTriangleBatches(const FrameGeometry& geometry, const BatchTrace& traceOne) {
    std::uint64_t needed = 0, limit = 0;
    std::string limitName;
    try {
        return traceOne(geometry, {});
    } catch (const gpu::DeviceLimitExceeded& e) {
        if (geometry.tracedTriangleCount() < 2) throw;
        needed = e.needed;
        limit = e.limit;
        limitName = e.limitName;
    }
    const std::size_t parts = std::max<std::uint64_t>(2, (needed + limit - 1) / limit);
    const std::string why = "the whole frame needs " + std::to_string(needed) + " where the device allows " +
                            std::to_string(limit) + " (" + limitName + "): its triangles traced in batches (the " +
                            "first one's plan above), their hits merged";
    const std::vector<WorkLine> planLines = {{"triangle batches (at least)", parts, why}};
    std::size_t batches = 0;
    std::optional<TraceResult> merged;
    for (std::vector<std::uint32_t>& ids : splitIds(tracedIds(geometry), parts)) {
        TraceResult r = traceSplitting(geometry, std::move(ids), traceOne, Excess{limitName, needed}, planLines, batches);
        if (r.hits.size() != geometry.rays->size()) return r;  // stopped at its plan
        if (merged) mergeBatch(*merged, r, geometry.query);
        else merged = std::move(r);
    }
    merged->memory.addWork("triangle batches", batches, why);
    return std::move(*merged);
}

}  // namespace dacrt
