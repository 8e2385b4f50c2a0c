// The predicates of the non-default DACRT options (dacrt/option_predicates.hpp) on known cases;
// docs/benchmarks.md prices them on real scenes.
#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "cpu/option_predicates.hpp"

namespace dacrt {
namespace {

TEST(OptionPredicates, SeparatingAxesRejectWhatBoundsAcceptAndKeepTouchingTriangles) {
    Triangle diagonal{};
    diagonal.v0 = {2, 0, 0};
    diagonal.v1 = {0, 2, 0};
    diagonal.v2 = {2, 2, 0};  // bounds [0,2]^2 overlap the unit box, the triangle does not
    const Bounds b = triangleBounds(diagonal);
    EXPECT_TRUE(shared::boundsOverlap(b.lo, b.hi, glm::vec3(0, 0, -1), glm::vec3(0.9f, 0.9f, 1)));
    EXPECT_FALSE(triangleOverlapsBoxSat(diagonal, b, glm::vec3(0, 0, -1), glm::vec3(0.9f, 0.9f, 1)));
    EXPECT_TRUE(triangleOverlapsBoxSat(diagonal, b, glm::vec3(0, 0, -1), glm::vec3(1, 1, 1)));  // touches at (1,1)
    Triangle flat{};  // in the plane z = 1, the box's face
    flat.v0 = {0, 0, 1};
    flat.v1 = {1, 0, 1};
    flat.v2 = {0, 1, 1};
    EXPECT_TRUE(triangleOverlapsBoxSat(flat, triangleBounds(flat), glm::vec3(0, 0, 0), glm::vec3(1, 1, 1)));
}

TEST(OptionPredicates, MollerTrumboreAgreesWithWatertightAwayFromEdges) {
    // Two triangles sharing the edge x = 0 of the square [-1, 1]^2 at z = -2; the ray hits the
    // left one well inside.
    const Triangle left{{-1, -1, -2}, 0, {0, -1, -2}, 0, {0, 1, -2}, 0};
    const Triangle right{{0, -1, -2}, 0, {1, -1, -2}, 0, {0, 1, -2}, 0};
    const Ray ray = makeRay(glm::vec3(0.0f), {-0.5, -0.2, -2});
    const shared::TriangleHit mt = intersectMollerTrumbore(ray, left.v0, left.v1, left.v2, false);
    const shared::TriangleHit wt = shared::intersectWatertight(ray, left.v0, left.v1, left.v2, false);
    ASSERT_TRUE(mt.hit && wt.hit);
    EXPECT_NEAR(mt.t, wt.t, 1e-6 * wt.t);
    EXPECT_NEAR(mt.u, wt.u, 1e-5);
    EXPECT_NEAR(mt.v, wt.v, 1e-5);
    EXPECT_FALSE(intersectMollerTrumbore(ray, right.v0, right.v1, right.v2, false).hit);
}

}  // namespace
}  // namespace dacrt
