// A frame's passes over its triangles and rays, made faster, give the sequential code's bits:
// the triangle bounds in lanes (triangle_bounds_lanes.hpp) on every SIMD target this machine
// runs, signed zeros and ties included, and the bounds, the rays' shared start and reach
// (frameGeometry) and the hits' start (through a trace) on one thread and on two.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "core/camera.hpp"
#include "core/random.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "core/triangle_bounds_lanes.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/simd_kernels.hpp"
#include "support/frames.hpp"

namespace dacrt {
namespace {

using test::identicalHits;
using test::traceFrame;

template <typename T>
bool sameBytes(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool sameBox(const Box& a, const Box& b) { return sameBytes(a.lo, b.lo) && sameBytes(a.hi, b.hi); }

// Coordinates drawn from few values, signed zeros among them, so that vertices tie on an axis
// (which of two equal values min keeps shows only in a zero's sign); the words beside the
// vertices (cullBackFace, padding) set, which the bounds must not copy.
std::vector<Triangle> tyingTriangles(std::size_t count, std::uint64_t seed) {
    const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -2.5f, 3.0f};
    Random random(seed);
    auto coordinate = [&] { return values[random.index(std::size(values))]; };
    auto vertex = [&] { return glm::vec3(coordinate(), coordinate(), coordinate()); };
    std::vector<Triangle> triangles(count);
    for (Triangle& t : triangles) {
        t.v0 = vertex();
        t.v1 = vertex();
        t.v2 = vertex();
        t.cullBackFace = std::uint32_t(random.index(2));
        t.pad1 = -7.0f;
        t.pad2 = 1e30f;
    }
    return triangles;
}

class FrameScansOnEveryTarget : public ::testing::Test {
protected:
    template <typename Body>
    void forEachTarget(Body body) {
        for (const std::string& t : simd::availableTargets()) {
            SCOPED_TRACE("target " + t);
            simd::forceTarget(t);
            body();
        }
    }
    void TearDown() override { simd::forceTarget(""); }
};

TEST_F(FrameScansOnEveryTarget, TriangleBoundsInLanesAreTheScalarLoops) {
    const std::vector<Triangle> triangles = tyingTriangles(5000, 20261206);
    std::vector<Bounds> expected(triangles.size());
    Box expectedBox;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        expected[i] = triangleBounds(triangles[i]);
        expectedBox.extend(triangles[i].v0);
        expectedBox.extend(triangles[i].v1);
        expectedBox.extend(triangles[i].v2);
    }
    forEachTarget([&] {
        std::vector<Bounds> bounds(triangles.size());
        Box box;
        triangleBoundsLanes(triangles.data(), triangles.size(), bounds.data(), box);
        for (std::size_t i = 0; i < triangles.size(); ++i) ASSERT_TRUE(sameBytes(bounds[i], expected[i])) << "triangle " << i;
        EXPECT_TRUE(sameBox(box, expectedBox));
    });
}

// The box of the lanes starts from the caller's, as Box::extend continues one.
TEST_F(FrameScansOnEveryTarget, TriangleBoundsInLanesExtendTheGivenBox) {
    const std::vector<Triangle> triangles = tyingTriangles(7, 5);
    forEachTarget([&] {
        Box expected;
        expected.extend(glm::vec3(-0.0f, 9.0f, 0.0f));
        Box box = expected;
        for (const Triangle& t : triangles) expected.extend(t.v0), expected.extend(t.v1), expected.extend(t.v2);
        std::vector<Bounds> bounds(triangles.size());
        triangleBoundsLanes(triangles.data(), triangles.size(), bounds.data(), box);
        EXPECT_TRUE(sameBox(box, expected));
    });
}

// Three chunks and a part (the parallel bounds take 16,384 triangles a chunk, the rays' scans
// as many rays), on one thread and on two.
TEST(FrameScans, BoundsAndRaysScannedSideBySideAreTheSequentialOnes) {
    const std::vector<Triangle> triangles = tyingTriangles(3 * 16384 + 1000, 77);
    const std::vector<Bounds> expected = allTriangleBounds(triangles);
    const Box expectedBox = sceneBounds(triangles);
    ThreadPool one(1), two(2);
    for (ThreadPool* pool : {&one, &two}) {
        std::vector<Bounds> bounds;
        Box box;
        triangleBoundsInParallel(triangles, *pool, bounds, box);
        ASSERT_EQ(bounds.size(), expected.size());
        EXPECT_EQ(std::memcmp(bounds.data(), expected.data(), bounds.size() * sizeof(Bounds)), 0);
        EXPECT_TRUE(sameBox(box, expectedBox));
    }

    // Rays from one point, then the same rays with one origin moved in the last chunk and one
    // tmin changed in the first: the shared start found or refused on every pool, and the
    // rays' reach (farthest origin, child order) the sequential one.
    std::vector<Ray> rays(3 * 16384 + 500);
    Random random(3);
    for (Ray& r : rays) r = makeRay(glm::vec3(0.25f, -1.0f, 2.0f), glm::dvec3(random.onSphere()), 0.0f);
    const Box sceneBox = sceneBounds(triangles);
    for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &one, &two}) {
        EXPECT_TRUE(raysShareStart(rays, pool));
        EXPECT_TRUE(frameGeometry(triangles, expected, rays, sceneBox, 0, pool).raysShareStart);
    }
    std::vector<Ray> moved = rays;
    moved[moved.size() - 3].origin.x = -4.0f;
    std::vector<Ray> later = rays;
    later[5].tmin = 0x1p-20f;
    const FrameGeometry sequential = frameGeometry(triangles, expected, moved, sceneBox);
    for (ThreadPool* pool : {&one, &two}) {
        EXPECT_FALSE(raysShareStart(moved, pool));
        EXPECT_FALSE(raysShareStart(later, pool));
        const FrameGeometry g = frameGeometry(triangles, expected, moved, sceneBox, 0, pool);
        EXPECT_FALSE(g.raysShareStart);
        EXPECT_TRUE(sameBytes(g.farthestOrigin, sequential.farthestOrigin));
        EXPECT_TRUE(sameBytes(g.nearSide, sequential.nearSide));
        EXPECT_EQ(g.order, sequential.order);
        EXPECT_EQ(g.margin, sequential.margin);
        EXPECT_EQ(g.farthestOrigin.x, 4.0f);
    }
}

// Any-hit rays from many points toward a wall they would meet at t = 1, every segment ending
// before it but one in the last chunk of the hits' start: the rays do not share a segment,
// found on two threads as on one, so the ray filter does not take the first ray's segment for
// that ray's (SharedRayFields::Segment), and it hits, as brute force says.
TEST(FrameScans, ASegmentEndingEarlyInTheLastChunkIsSeenOnTwoThreads) {
    Scene wall;
    Triangle t{};
    t.v0 = {-100, -100, 0};
    t.v1 = {100, -100, 0};
    t.v2 = {0, 100, 0};
    wall.triangles.push_back(t);
    const std::vector<Bounds> bounds = allTriangleBounds(wall.triangles);
    std::vector<Ray> rays;
    for (int i = 0; i < 3 * 16384 + 100; ++i)
        rays.push_back(makeRay({float(i % 100) * 0.1f - 5.0f, float(i / 100) * 0.01f - 2.0f, -1.0f}, {0, 0, 1}));
    for (std::size_t i = 0; i + 1 < rays.size(); ++i) rays[i].tmax = 0.5f;
    FrameGeometry g = frameGeometry(wall.triangles, bounds, rays, sceneBounds(wall.triangles));
    g.query = HitQuery::Any;
    const TraceResult reference = traceFrame(g, Backend::Brute);
    ASSERT_NE(reference.hits.back().prim, kMissPrim);
    ASSERT_EQ(reference.hits.front().prim, kMissPrim);
    for (unsigned regions : {1u, 2u})
        EXPECT_TRUE(identicalHits(reference.hits, traceFrame(g, Backend::Cpu, regions, 2).hits)) << regions;
}

}  // namespace
}  // namespace dacrt
