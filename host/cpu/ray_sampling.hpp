#pragma once
// The ray-sampling cost of Nabata et al. 2013 ("Efficient Divide-And-Conquer Ray Tracing using
// Ray Sampling"), the SplitCost::RaySampling option: a fixed sample of a node's rays and
// triangles estimates how many of each every candidate child would keep, and so the work of
// splitting against that of a leaf. A node whose rays no split separates enough stays a
// leaf; otherwise it splits where the estimate is lowest, on whichever axis that is.
#include <cstdint>

#include "core/scene.hpp"
#include "core/shader_layout.hpp"

namespace dacrt {

// Relative costs of the estimate, one ray/triangle test of a leaf being 1: filtering a ray
// into a child is a slab test (about a leaf test's work); a triangle's filter compares its
// bounds with one face of the child cell. Weights 4x and 0.25x these moved the counters by
// 6% at most (docs/benchmarks.md): the children's products outweigh the filters.
constexpr double kSampledRayBoxCost = 1.0;
constexpr double kSampledTriangleBoxCost = 0.5;
// About this many rays and as many triangles are sampled per node (every k-th one, no random
// state: the same node always makes the same decision), so never twice as many.
constexpr std::uint32_t kSampledItems = 32;
// A node whose leaf would cost less (rays x triangles) splits as the limits say, on the
// longest axis at the split method's position, unsampled: there the sample's own work
// costs more than a better split saves (measured: docs/benchmarks.md).
constexpr double kSampledMinLeafCost = 16000.0;

// A node's live rays and triangles, as the traversal's id arrays hold them, and the leaf
// limits that its children meet.
struct SampledNode {
    const Ray* rays = nullptr;
    const Hit* hits = nullptr;  // each ray's best hit so far: a child beyond it is not entered
    const std::uint32_t* rayIds = nullptr;
    std::uint32_t rayCount = 0;
    const Bounds* triangleBounds = nullptr;
    const std::uint32_t* triIds = nullptr;
    std::uint32_t triCount = 0;
    std::uint32_t rayLimit = 0, triLimit = 0;
};

struct SplitChoice {
    bool split = false;       // false: the node is cheaper as a leaf
    int axis = 0;             // the axis to split (when split)
    float position = 0.0f;    // where to split along it
    double leafCost = 0.0;    // rays x triangles
    double splitCost = 0.0;   // the cheapest candidate's filters plus its children's estimates
    std::uint64_t rayBoxTests = 0;  // the sample's ray/box tests, for the traversal's counters
};

// The candidates are, on each axis of box, its midpoint (methodPosition, the split method's,
// on `axis`) and its quarter points, each strictly inside box; cells are the children widened
// by margin, as the traversal filters them. A node under kSampledMinLeafCost splits on axis at
// methodPosition.
SplitChoice chooseSplitByRaySampling(const SampledNode& node, const Box& box, int axis, float margin,
                                     float methodPosition);

}  // namespace dacrt
