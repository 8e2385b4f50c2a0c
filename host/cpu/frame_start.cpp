#include "cpu/frame_start.hpp"

#include <algorithm>

#include "core/mapped_memory.hpp"

namespace dacrt {

void planFrameInputs(const FrameGeometry& g, MemoryPlan& plan) { planFrameInputs(g, g.rays->size(), plan); }

void planFrameInputs(const FrameGeometry& g, std::uint64_t rayCount, MemoryPlan& plan) {
    plan.add("rays", rayCount * sizeof(Ray));
    plan.add("hits", rayCount * sizeof(Hit));
    plan.add("triangles", std::uint64_t(g.triangles->size()) * sizeof(Triangle));
    plan.add("triangle bounds", std::uint64_t(g.triangles->size()) * sizeof(Bounds));
    if (g.boundsColumns) plan.add("triangle bounds in columns", std::uint64_t(g.boundsColumns->size()) * sizeof(float));
}

bool startHits(const FrameGeometry& g, std::vector<Hit>& hits, ThreadPool* pool) {
    const std::vector<Ray>& rays = *g.rays;
    if (g.uniformByConstruction) {  // one segment: every start the first ray's, the rays unread
        hits = filledArray(rays.size(), missHit(rays[0]), pool);
        return true;
    }
    reserveMapped(hits, rays.size());
    hits.resize(rays.size());
    std::vector<std::uint8_t> shareSegment((rays.size() + kFrameScanChunk - 1) / kFrameScanChunk, 1);
    forEachChunk(rays.size(), kFrameScanChunk, pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
        bool share = true;
        for (std::size_t i = begin; i < end; ++i) {
            hits[i] = missHit(rays[i]);
            share &= sameSegment(rays[i], rays[0]);
        }
        shareSegment[c] = share;
    });
    return !rays.empty() && std::all_of(shareSegment.begin(), shareSegment.end(), [](std::uint8_t s) { return s != 0; });
}

}  // namespace dacrt
