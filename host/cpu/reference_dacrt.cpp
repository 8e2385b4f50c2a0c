#include "cpu/reference_dacrt.hpp"

#include <utility>

#include "cpu/predicates.hpp"
#include "cpu/trace_result.hpp"
#include "cpu/traversal.hpp"

namespace dacrt {
namespace {

using Ids = std::vector<std::uint32_t>;

// Which rays visit a child: all of them, or (ChildOrder::PerRay) those moving one way along the
// split axis.
struct RayClass {
    int axis = 0;
    int moving = 0;  // +1: up or not at all, -1: down, 0: every ray
    bool holds(const Ray& ray) const { return moving == 0 || (ray.dir[axis] < 0.0f) == (moving < 0); }
};

class ReferenceDacrt {
public:
    ReferenceDacrt(const FrameGeometry& g, const ReferenceLeafLimits& limits)
        : g_(g), limits_(limits), hits_(g.rays->size()), finished_(g.rays->size(), 0) {
        for (std::size_t i = 0; i < hits_.size(); ++i) hits_[i] = missHit((*g.rays)[i]);
    }

    std::vector<Hit> run() {
        Ids rays(g_.rays->size()), triangles(g_.tracedTriangleCount());
        for (std::uint32_t i = 0; i < rays.size(); ++i) rays[i] = i;
        for (std::uint32_t i = 0; i < triangles.size(); ++i) triangles[i] = g_.tracedTriangle(i);
        visit(g_.sceneBox, rays, triangles, 0, RayClass{});
        return std::move(hits_);
    }

private:
    // Code 2.1, lines 8-10: R' = R in E_i and P' = P in E_i, then DACRT(E_i, R', P'). Both filters
    // test the box widened by the filter margin, so that rounding never drops a ray or a
    // triangle it holds (docs/correctness.md, "The filter margin").
    void visit(const Box& box, const Ids& parentRays, const Ids& parentTriangles, std::uint32_t depth,
               const RayClass& rayClass) {
        const Box cell{box.lo - glm::vec3(g_.margin), box.hi + glm::vec3(g_.margin)};
        Ids rays, triangles;
        // Live rays only (finished ones are retired), each within [tmin, its best t so far]:
        // a hit found in an earlier cell shortens the ray for every later filter.
        for (std::uint32_t id : parentRays) {
            const Ray& ray = (*g_.rays)[id];
            if (!finished_[id] && rayClass.holds(ray) && shared::rayMayCrossCell(ray, cell.lo, cell.hi, hits_[id].t))
                rays.push_back(id);
        }
        for (std::uint32_t id : parentTriangles) {
            const Bounds& b = (*g_.triangleBounds)[id];
            if (shared::boundsOverlap(b.lo, b.hi, cell.lo, cell.hi)) triangles.push_back(id);
        }
        if (!rays.empty() && !triangles.empty()) node(box, rays, triangles, depth);
    }

    void node(const Box& box, const Ids& rays, const Ids& triangles, std::uint32_t depth) {
        // Line 5, SubdivideSpace: two halves at the spatial median of the longest axis...
        const glm::vec3 e = box.extent();
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const float split = 0.5f * (box.lo[axis] + box.hi[axis]);
        // ... unless (lines 2-3) few rays or few triangles remain, or the box no longer splits:
        // NaiveRT.
        if (rays.size() < limits_.rays || triangles.size() < limits_.triangles || depth >= limits_.maxDepth ||
            !(split > box.lo[axis] && split < box.hi[axis]))
            return naiveLeaf(box, rays, triangles);
        Box low = box, high = box;
        low.hi[axis] = split;
        high.lo[axis] = split;
        // Line 7, for each E_i, front to back: each child filtered from this node's R and P.
        if (g_.order == ChildOrder::NearSide) {
            // Every ray comes from the near side (FrameGeometry::nearSide).
            const bool lowIsNear = g_.nearSide[axis] <= split;
            visit(lowIsNear ? low : high, rays, triangles, depth + 1, RayClass{});
            visit(lowIsNear ? high : low, rays, triangles, depth + 1, RayClass{});
        } else if (g_.query == HitQuery::Any) {
            // Any hit ends a ray wherever it lies: the order changes no answer.
            visit(low, rays, triangles, depth + 1, RayClass{});
            visit(high, rays, triangles, depth + 1, RayClass{});
        } else {
            // ChildOrder::PerRay: each ray meets the children in the order its direction crosses them.
            visit(low, rays, triangles, depth + 1, RayClass{axis, +1});
            visit(high, rays, triangles, depth + 1, RayClass{axis, 0});
            visit(low, rays, triangles, depth + 1, RayClass{axis, -1});
        }
    }

    // NaiveRT: every ray against every triangle, the tie rule keeping the better hit. A hit ends
    // its ray (early termination) only if it lies inside this box: cells are visited front to
    // back, so none visited later holds a closer one; a hit beyond the box only shortens the
    // ray. Any hit ends its ray wherever it lies.
    void naiveLeaf(const Box& box, const Ids& rays, const Ids& triangles) {
        for (std::uint32_t id : rays) {
            const Ray& ray = (*g_.rays)[id];
            Hit& best = hits_[id];
            for (std::uint32_t prim : triangles) testTriangle(ray, (*g_.triangles)[prim], prim, best);
            if (best.prim != kMissPrim &&
                (g_.query == HitQuery::Any || shared::hitEndsInBox(ray, box.lo, box.hi, best.t)))
                finished_[id] = 1;
        }
    }

    const FrameGeometry& g_;
    ReferenceLeafLimits limits_;
    std::vector<Hit> hits_;
    std::vector<std::uint8_t> finished_;
};

}  // namespace

std::vector<Hit> traceReferenceDacrt(const FrameGeometry& geometry, const ReferenceLeafLimits& limits) {
    return ReferenceDacrt(geometry, limits).run();
}

}  // namespace dacrt
