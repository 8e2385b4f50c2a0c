#include "cpu/ray_sampling.hpp"

#include <algorithm>

#include "cpu/predicates.hpp"

namespace dacrt {
namespace {

std::uint32_t sampleStride(std::uint32_t count) { return std::max(1u, count / kSampledItems); }
constexpr std::uint32_t kMostSampled = 2 * kSampledItems;

// The sample as intervals along each axis: where each sampled ray runs inside the node's cell
// before its best hit so far, and each sampled triangle's bounds. A child cell differs from
// the node's in one face, on its split axis, and the node's rays cross the node's cell and
// its triangles overlap it, so an item meets a child where its interval on that axis meets
// the child's: each candidate costs comparisons only, one ray/box test per sampled ray in all.
struct Sample {
    float rayLo[3][kMostSampled], rayHi[3][kMostSampled];
    float triLo[3][kMostSampled], triHi[3][kMostSampled];
    std::uint32_t rays = 0, crossing = 0, triangles = 0;  // sampled, and the rays' intervals
};

void sampleRays(const SampledNode& node, const Box& cell, Sample& s) {
    const std::uint32_t stride = sampleStride(node.rayCount);
    for (std::uint32_t k = 0; k < node.rayCount; k += stride, ++s.rays) {
        const std::uint32_t id = node.rayIds[k];
        const Ray& ray = node.rays[id];
        const shared::RayInterval r = shared::rayBoxIntervalRounded(ray, cell.lo, cell.hi);
        const float tIn = std::max(r.tNear, ray.tmin), tOut = std::min(r.tFar, node.hits[id].t);
        if (!(tIn <= tOut)) continue;
        for (int a = 0; a < 3; ++a) {
            const float enter = ray.origin[a] + tIn * ray.dir[a], leave = ray.origin[a] + tOut * ray.dir[a];
            s.rayLo[a][s.crossing] = std::min(enter, leave);
            s.rayHi[a][s.crossing] = std::max(enter, leave);
        }
        ++s.crossing;
    }
}

void sampleTriangles(const SampledNode& node, Sample& s) {
    const std::uint32_t stride = sampleStride(node.triCount);
    for (std::uint32_t j = 0; j < node.triCount; j += stride, ++s.triangles) {
        const Bounds& b = node.triangleBounds[node.triIds[j]];
        for (int a = 0; a < 3; ++a) {
            s.triLo[a][s.triangles] = b.lo[a];
            s.triHi[a][s.triangles] = b.hi[a];
        }
    }
}

// The share, of `of` sampled items, of the n intervals that meet [lo, hi].
double share(const float* itemLo, const float* itemHi, std::uint32_t n, std::uint32_t of, float lo, float hi) {
    std::uint32_t kept = 0;  // branch-free, so that it vectorizes
    for (std::uint32_t i = 0; i < n; ++i) kept += std::uint32_t(itemLo[i] <= hi) & std::uint32_t(itemHi[i] >= lo);
    return of ? double(kept) / of : 0.0;
}

// A split at position on axis a: the filters, then each child's estimated rays x triangles.
// A child the limits do not make a leaf will be split again, and is priced as splitting as
// well as this split does (its cost shrinks by this split's ratio to the leaf), not as a leaf.
double candidateCost(const SampledNode& node, const Sample& s, const Box& cell, int a, float position, float margin,
                     double filters, double leafCost) {
    double rays[2], triangles[2], asLeaves = 0.0;
    for (int c = 0; c < 2; ++c) {
        const float lo = c == 0 ? cell.lo[a] : position - margin, hi = c == 0 ? position + margin : cell.hi[a];
        rays[c] = node.rayCount * share(s.rayLo[a], s.rayHi[a], s.crossing, s.rays, lo, hi);
        triangles[c] = node.triCount * share(s.triLo[a], s.triHi[a], s.triangles, s.triangles, lo, hi);
        asLeaves += rays[c] * triangles[c];
    }
    const double ratio = (filters + asLeaves) / leafCost;
    if (ratio >= 1.0) return filters + asLeaves;
    double cost = filters;
    for (int c = 0; c < 2; ++c) {
        const bool splitAgain = rays[c] >= node.rayLimit && triangles[c] >= node.triLimit;
        cost += rays[c] * triangles[c] * (splitAgain ? ratio : 1.0);
    }
    return cost;
}

}  // namespace

SplitChoice chooseSplitByRaySampling(const SampledNode& node, const Box& box, int axis, float margin,
                                     float methodPosition) {
    SplitChoice choice;
    choice.leafCost = double(node.rayCount) * node.triCount;
    choice.splitCost = choice.leafCost;
    choice.axis = axis;
    if (choice.leafCost < kSampledMinLeafCost) {  // unsampled: split as the limits do
        choice.split = true;
        choice.position = methodPosition;
        return choice;
    }
    Box cell = box;
    cell.lo -= glm::vec3(margin);
    cell.hi += glm::vec3(margin);
    Sample s;
    sampleRays(node, cell, s);
    sampleTriangles(node, s);
    choice.rayBoxTests = s.rays;
    const double filters = 2.0 * (node.rayCount * kSampledRayBoxCost + node.triCount * kSampledTriangleBoxCost);
    for (int a = 0; a < 3; ++a) {
        const float lo = box.lo[a], hi = box.hi[a];
        const float candidates[3] = {a == axis ? methodPosition : 0.5f * (lo + hi), lo + 0.25f * (hi - lo),
                                     lo + 0.75f * (hi - lo)};
        for (const float position : candidates) {
            if (!(position > lo && position < hi)) continue;
            const double cost = candidateCost(node, s, cell, a, position, margin, filters, choice.leafCost);
            if (cost < choice.splitCost) {
                choice.split = true;
                choice.axis = a;
                choice.position = position;
                choice.splitCost = cost;
            }
        }
    }
    return choice;
}

}  // namespace dacrt
