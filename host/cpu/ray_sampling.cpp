#include "cpu/ray_sampling.hpp"

#include <algorithm>

#include "cpu/predicates.hpp"

namespace dacrt {
namespace {

std::uint32_t sampleStride(std::uint32_t count) { return std::max(1u, count / kSampledItems); }

// Fractions of the sampled rays and triangles a child cell keeps.
struct ChildShare {
    double rays = 0.0;
    double triangles = 0.0;
};

ChildShare sampleChild(const SampledNode& node, const Box& cell, std::uint64_t& rayBoxTests) {
    std::uint32_t rays = 0, raysKept = 0, tris = 0, trisKept = 0;
    for (std::uint32_t k = 0; k < node.rayCount; k += sampleStride(node.rayCount), ++rays) {
        const std::uint32_t id = node.rayIds[k];
        raysKept += shared::rayMayCrossCell(node.rays[id], cell.lo, cell.hi, node.hits[id].t) ? 1u : 0u;
    }
    for (std::uint32_t j = 0; j < node.triCount; j += sampleStride(node.triCount), ++tris) {
        const Bounds& b = node.triangleBounds[node.triIds[j]];
        trisKept += shared::boundsOverlap(b.lo, b.hi, cell.lo, cell.hi) ? 1u : 0u;
    }
    rayBoxTests += rays;
    return {rays ? double(raysKept) / rays : 0.0, tris ? double(trisKept) / tris : 0.0};
}

}  // namespace

SplitChoice chooseSplitByRaySampling(const SampledNode& node, const Box& box, int axis, float margin,
                                     float methodPosition) {
    SplitChoice choice;
    const double rays = node.rayCount, triangles = node.triCount;
    choice.leafCost = rays * triangles;
    choice.splitCost = choice.leafCost;
    const float lo = box.lo[axis], hi = box.hi[axis];
    const float candidates[3] = {methodPosition, lo + 0.25f * (hi - lo), lo + 0.75f * (hi - lo)};
    const double filters = 2.0 * (rays * kSampledRayBoxCost + triangles * kSampledTriangleBoxCost);
    for (const float position : candidates) {
        if (!(position > lo && position < hi)) continue;
        double cost = filters;
        for (const bool low : {true, false}) {
            Box cell = box;
            (low ? cell.hi : cell.lo)[axis] = position;
            cell.lo -= glm::vec3(margin);
            cell.hi += glm::vec3(margin);
            const ChildShare share = sampleChild(node, cell, choice.rayBoxTests);
            cost += share.rays * rays * share.triangles * triangles;
        }
        if (cost < choice.splitCost) {
            choice.split = true;
            choice.position = position;
            choice.splitCost = cost;
        }
    }
    return choice;
}

}  // namespace dacrt
