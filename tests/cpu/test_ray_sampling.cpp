// The ray-sampling cost's decision (SplitCost::RaySampling) on a small node: rays that every
// child would keep make a leaf; rays a split separates make a split, where and on whichever
// axis it separates most; children the limits do not end are priced as splitting again; a
// node too small to sample splits as the limits say.
#include <vector>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "cpu/ray_sampling.hpp"

namespace dacrt {
namespace {

constexpr std::uint32_t kItems = 128;  // rays and triangles: 128 x 128 is above kSampledMinLeafCost
static_assert(double(kItems) * kItems >= kSampledMinLeafCost);

// Thin triangles' bounds spread evenly along x over the unit cube, in the band 0.4-0.6 of y
// and z (or spread along y over a box up to hi, each spanning its x), and rays added with them
// (the node holds every ray and triangle).
struct TinyNode {
    Box box;
    std::vector<Bounds> bounds;
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    std::vector<std::uint32_t> rayIds, triIds;

    explicit TinyNode(glm::vec3 hi = glm::vec3(1.0f), int spread = 0, std::uint32_t triangles = kItems) {
        box.lo = glm::vec3(0.0f);
        box.hi = hi;
        for (std::uint32_t i = 0; i < triangles; ++i) {
            const float at = (float(i) + 0.5f) / float(triangles) * hi[spread];
            Bounds b;
            b.lo = glm::vec3(0.0f, 0.4f, 0.4f);
            b.hi = glm::vec3(hi.x, 0.6f, 0.6f);
            b.lo[spread] = at - 0.001f;
            b.hi[spread] = at + 0.001f;
            bounds.push_back(b);
            triIds.push_back(i);
        }
    }
    void addRay(const Ray& ray, float bestT = kNoHitT) {
        rayIds.push_back(std::uint32_t(rays.size()));
        rays.push_back(ray);
        hits.push_back(Hit{bestT, kMissPrim, 0.0f, 0.0f});
    }
    SplitChoice choose(std::uint32_t rayLimit = 16, std::uint32_t triLimit = 64) const {
        const SampledNode node{rays.data(),   hits.data(),   rayIds.data(),
                               std::uint32_t(rays.size()), bounds.data(), triIds.data(),
                               std::uint32_t(triIds.size()), rayLimit,      triLimit};
        return chooseSplitByRaySampling(node, box, 0, 1e-4f, 0.5f * box.hi.x);
    }
};

// Along x through the whole node, spread over y across the triangles' band.
void addRaysAlongX(TinyNode& node, float bestT = kNoHitT) {
    for (std::uint32_t i = 0; i < kItems; ++i)
        node.addRay(makeRay(glm::vec3(-1.0f, 0.4f + 0.0015f * float(i), 0.5f), glm::dvec3(1.0, 0.0, 0.0)), bestT);
}

// Along y, one per triangle column: each ray meets one child of any split along x.
void addRaysAlongY(TinyNode& node) {
    for (std::uint32_t i = 0; i < kItems; ++i)
        node.addRay(makeRay(glm::vec3((float(i) + 0.5f) / float(kItems), -1.0f, 0.5f), glm::dvec3(0.0, 1.0, 0.0)));
}

TEST(RaySamplingCost, RaysThatEnterEveryChildMakeALeaf) {
    TinyNode node;
    // No split on any axis helps: along x every ray meets both children; along y and z the
    // triangles' band lies across the midpoint (both children keep them all) or in one child.
    addRaysAlongX(node);
    const SplitChoice c = node.choose();
    EXPECT_FALSE(c.split) << "split cost " << c.splitCost << " against leaf " << c.leafCost;
    EXPECT_GE(c.splitCost, c.leafCost);
    EXPECT_GT(c.rayBoxTests, 0u);
}

TEST(RaySamplingCost, RaysThatSeparateMakeASplitAtTheBestCandidate) {
    TinyNode node;
    addRaysAlongY(node);
    const SplitChoice c = node.choose();
    ASSERT_TRUE(c.split);
    EXPECT_LT(c.splitCost, 0.6 * c.leafCost);
    // Halving both rays and triangles beats the quarter points' quarter and three quarters.
    EXPECT_EQ(c.axis, 0);
    EXPECT_EQ(c.position, 0.5f);
}

TEST(RaySamplingCost, ABestHitSoFarKeepsARayOutOfTheFarChild) {
    TinyNode node;
    // As in the leaf case, but each ray already has a hit a fifth of the way in: no ray reaches
    // the high children, so a split sends each ray to a part of the triangles only.
    addRaysAlongX(node, 1.2f);
    const SplitChoice c = node.choose();
    ASSERT_TRUE(c.split);
    EXPECT_EQ(c.axis, 0);
    EXPECT_EQ(c.position, 0.25f);
    // The same node gives the same decision (a fixed sample, no random state).
    const SplitChoice again = node.choose();
    EXPECT_EQ(again.axis, c.axis);
    EXPECT_EQ(again.position, c.position);
    EXPECT_EQ(again.splitCost, c.splitCost);
}

TEST(RaySamplingCost, AnotherAxisThatSeparatesTheRaysIsChosen) {
    // A node twice as long along x (the traversal's axis), its triangles spread along y and
    // each spanning x, its rays along x: any split along x keeps every ray and triangle in both
    // children, the midpoint of y halves both.
    TinyNode node(glm::vec3(2.0f, 1.0f, 1.0f), 1);
    for (std::uint32_t i = 0; i < kItems; ++i)
        node.addRay(makeRay(glm::vec3(-1.0f, (float(i) + 0.5f) / float(kItems), 0.5f), glm::dvec3(1.0, 0.0, 0.0)));
    const SplitChoice c = node.choose();
    ASSERT_TRUE(c.split);
    EXPECT_EQ(c.axis, 1);
    EXPECT_EQ(c.position, 0.5f);
    EXPECT_LT(c.splitCost, 0.6 * c.leafCost);
}

TEST(RaySamplingCost, ChildrenAboveTheLimitsArePricedAsSplittingAgain) {
    TinyNode node;
    addRaysAlongY(node);
    // Limits above the children's counts make them leaves: priced as rays x triangles.
    const SplitChoice asLeaves = node.choose(kItems, kItems);
    // Limits of 1 leave them to split again: each costs its leaf times the split's ratio.
    const SplitChoice again = node.choose(1, 1);
    ASSERT_TRUE(asLeaves.split);
    ASSERT_TRUE(again.split);
    EXPECT_EQ(again.position, asLeaves.position);
    const double ratio = asLeaves.splitCost / asLeaves.leafCost;
    const double filters = 2.0 * (kItems * kSampledRayBoxCost + kItems * kSampledTriangleBoxCost);
    EXPECT_NEAR(again.splitCost, filters + (asLeaves.splitCost - filters) * ratio, 1e-6 * again.leafCost);
    EXPECT_LT(again.splitCost, asLeaves.splitCost);
}

TEST(RaySamplingCost, ANodeTooSmallToSampleSplitsAsTheLimitsSay) {
    TinyNode node(glm::vec3(1.0f), 0, 16);
    addRaysAlongX(node);  // 128 rays x 16 triangles: under kSampledMinLeafCost
    const SplitChoice c = node.choose();
    EXPECT_TRUE(c.split);
    EXPECT_EQ(c.axis, 0);
    EXPECT_EQ(c.position, 0.5f);
    EXPECT_EQ(c.rayBoxTests, 0u);
}

}  // namespace
}  // namespace dacrt
