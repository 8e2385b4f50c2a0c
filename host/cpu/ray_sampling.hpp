#pragma once
// The ray-sampling cost of Nabata et al. 2013 ("Efficient Divide-And-Conquer Ray Tracing using
// Ray Sampling"), the SplitCost::RaySampling option: a fixed sample of a node's rays and
// triangles estimates how many of each every candidate child would keep, and so the work of
// splitting against that of a leaf. A node whose rays a split does not separate enough stays
// a leaf; otherwise it splits where the estimate is lowest.
#include <cstdint>

#include "core/scene.hpp"
#include "core/shader_layout.hpp"

namespace dacrt {

// Relative costs of the estimate, one ray/triangle test of a leaf being 1: filtering a ray
// into a child is a slab test (about a leaf test's work); a triangle's filter compares its
// bounds with one face of the child cell.
constexpr double kSampledRayBoxCost = 1.0;
constexpr double kSampledTriangleBoxCost = 0.5;
// About this many rays and as many triangles are sampled per node (every k-th one, no random
// state: the same node always makes the same decision).
constexpr std::uint32_t kSampledItems = 32;

// A node's live rays and triangles, as the traversal's id arrays hold them.
struct SampledNode {
    const Ray* rays = nullptr;
    const Hit* hits = nullptr;  // each ray's best hit so far: a child beyond it is not entered
    const std::uint32_t* rayIds = nullptr;
    std::uint32_t rayCount = 0;
    const Bounds* triangleBounds = nullptr;
    const std::uint32_t* triIds = nullptr;
    std::uint32_t triCount = 0;
};

struct SplitChoice {
    bool split = false;       // false: the node is cheaper as a leaf
    float position = 0.0f;    // where to split along the axis (when split)
    double leafCost = 0.0;    // rays x triangles
    double splitCost = 0.0;   // the cheapest candidate's filters plus its children as leaves
    std::uint64_t rayBoxTests = 0;  // the sample's ray/box tests, for the traversal's counters
};

// The candidates are methodPosition (the split method's) and the axis's quarter points, each
// strictly inside box; cells are the children widened by margin, as the traversal filters them.
SplitChoice chooseSplitByRaySampling(const SampledNode& node, const Box& box, int axis, float margin,
                                     float methodPosition);

}  // namespace dacrt
