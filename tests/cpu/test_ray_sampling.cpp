// The ray-sampling cost's decision (SplitCost::RaySampling) on a tiny node: rays that every
// child would keep make a leaf; rays a split separates make a split, where it separates most.
#include <vector>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "cpu/ray_sampling.hpp"

namespace dacrt {
namespace {

// 64 small triangles' bounds spread evenly along x over the unit cube, and rays numbered with
// them (the node holds every ray and triangle).
struct TinyNode {
    Box box;
    std::vector<Bounds> bounds;
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    std::vector<std::uint32_t> rayIds, triIds;

    TinyNode() {
        box.lo = glm::vec3(0.0f);
        box.hi = glm::vec3(1.0f);
        for (std::uint32_t i = 0; i < 64; ++i) {
            const float x = (float(i) + 0.5f) / 64.0f;
            Bounds b;
            b.lo = glm::vec3(x - 0.001f, 0.4f, 0.4f);
            b.hi = glm::vec3(x + 0.001f, 0.6f, 0.6f);
            bounds.push_back(b);
            triIds.push_back(i);
        }
    }
    void addRay(const Ray& ray, float bestT = kNoHitT) {
        rayIds.push_back(std::uint32_t(rays.size()));
        rays.push_back(ray);
        hits.push_back(Hit{bestT, kMissPrim, 0.0f, 0.0f});
    }
    SplitChoice choose() const {
        const SampledNode node{rays.data(), hits.data(), rayIds.data(), std::uint32_t(rays.size()),
                               bounds.data(), triIds.data(), std::uint32_t(triIds.size())};
        return chooseSplitByRaySampling(node, box, 0, 1e-4f, 0.5f);
    }
};

TEST(RaySamplingCost, RaysThatEnterEveryChildMakeALeaf) {
    TinyNode node;
    // Along x through the whole node: every ray meets every candidate's both children.
    for (int i = 0; i < 64; ++i)
        node.addRay(makeRay(glm::vec3(-1.0f, 0.4f + 0.003f * i, 0.5f), glm::dvec3(1.0, 0.0, 0.0)));
    const SplitChoice c = node.choose();
    EXPECT_FALSE(c.split) << "split cost " << c.splitCost << " against leaf " << c.leafCost;
    EXPECT_GE(c.splitCost, c.leafCost);
    EXPECT_GT(c.rayBoxTests, 0u);
}

TEST(RaySamplingCost, RaysThatSeparateMakeASplitAtTheBestCandidate) {
    TinyNode node;
    // Along y, one per triangle column: each ray meets one child of any split along x.
    for (int i = 0; i < 64; ++i)
        node.addRay(makeRay(glm::vec3((float(i) + 0.5f) / 64.0f, -1.0f, 0.5f), glm::dvec3(0.0, 1.0, 0.0)));
    const SplitChoice c = node.choose();
    ASSERT_TRUE(c.split);
    EXPECT_LT(c.splitCost, 0.6 * c.leafCost);
    // Halving both rays and triangles beats the quarter points' quarter and three quarters.
    EXPECT_EQ(c.position, 0.5f);
}

TEST(RaySamplingCost, ABestHitSoFarKeepsARayOutOfTheFarChild) {
    TinyNode node;
    // As in the leaf case, but each ray already has a hit a fifth of the way in: no ray reaches
    // the high children, so a split sends each ray to a part of the triangles only.
    for (int i = 0; i < 64; ++i)
        node.addRay(makeRay(glm::vec3(-1.0f, 0.4f + 0.003f * i, 0.5f), glm::dvec3(1.0, 0.0, 0.0)), 1.2f);
    const SplitChoice c = node.choose();
    ASSERT_TRUE(c.split);
    EXPECT_EQ(c.position, 0.25f);
    // The same node gives the same decision (a fixed sample, no random state).
    const SplitChoice again = node.choose();
    EXPECT_EQ(again.position, c.position);
    EXPECT_EQ(again.splitCost, c.splitCost);
}

}  // namespace
}  // namespace dacrt
