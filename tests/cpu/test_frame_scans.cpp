// A frame's passes over its triangles and rays, made faster, give the sequential code's bits:
// the triangle bounds in lanes (triangle_bounds_lanes.hpp) on every SIMD target this machine
// runs, signed zeros and ties included, and the bounds, the rays' shared start and reach
// (frameGeometry) with the pool and without, and the hits' start (through a trace on two
// threads) as brute force sees the rays.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

#include "core/camera.hpp"
#include "core/random.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "core/triangle_bounds_lanes.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/simd_kernels.hpp"
#include "support/simd_targets.hpp"
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

using FrameScansOnEveryTarget = test::OnEveryTarget;

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

// Three chunks and a part (the parallel bounds take 16,384 triangles a chunk), on one thread
// and on two; with the columns, every coordinate of every record in its column, bit for bit,
// also where the columns' memory held a larger frame's.
TEST(FrameScans, BoundsComputedSideBySideAreTheSequentialOnes) {
    const std::vector<Triangle> triangles = tyingTriangles(3 * 16384 + 1000, 77);
    const std::vector<Bounds> expected = allTriangleBounds(triangles);
    const Box expectedBox = sceneBounds(triangles);
    ThreadPool one(1), two(2);
    for (ThreadPool* pool : {&one, &two})
        for (const bool withColumns : {false, true}) {
            std::vector<Bounds> bounds;
            std::vector<float> columns(7 * triangles.size(), 5.0f);
            Box box;
            triangleBoundsInParallel(triangles, *pool, bounds, box, withColumns ? &columns : nullptr);
            ASSERT_EQ(bounds.size(), expected.size());
            EXPECT_EQ(std::memcmp(bounds.data(), expected.data(), bounds.size() * sizeof(Bounds)), 0);
            EXPECT_TRUE(sameBox(box, expectedBox));
            if (!withColumns) continue;
            const std::size_t n = triangles.size();
            ASSERT_EQ(columns.size(), 6 * n);
            std::size_t differing = 0;
            for (std::size_t i = 0; i < n; ++i)
                for (int a = 0; a < 3; ++a) {
                    differing += std::memcmp(&columns[std::size_t(a) * n + i], &expected[i].lo[a], sizeof(float)) != 0;
                    differing += std::memcmp(&columns[std::size_t(3 + a) * n + i], &expected[i].hi[a], sizeof(float)) != 0;
                }
            EXPECT_EQ(differing, 0u);
        }
}

// Rays from one point, then the same rays with one origin moved in the last chunk or one tmin
// changed in the first: the shared start found or refused with and without the pool. Rays
// from many points into the positive octant, one of them in the last chunk turned back along
// x or not: the reach (farthest origin, near side, child order) what a plain loop gives.
TEST(FrameScans, RaysScannedSideBySideGiveThePlainLoopsAnswers) {
    const std::vector<Triangle> triangles = tyingTriangles(100, 78);
    const std::vector<Bounds> bounds = allTriangleBounds(triangles);
    const Box sceneBox = sceneBounds(triangles);
    ThreadPool two(2);
    std::vector<Ray> rays(3 * 16384 + 500);
    Random random(3);
    for (Ray& r : rays) r = makeRay(glm::vec3(0.25f, -1.0f, 2.0f), glm::dvec3(random.onSphere()), 0.0f);
    for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &two}) {
        EXPECT_TRUE(raysShareStart(rays, pool));
        EXPECT_TRUE(frameGeometry(triangles, bounds, rays, sceneBox, 0, pool).raysShareStart);
    }
    std::vector<Ray> moved = rays;
    moved[moved.size() - 3].origin.x = -4.0f;
    std::vector<Ray> later = rays;
    later[5].tmin = 0x1p-20f;
    for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &two}) {
        EXPECT_FALSE(raysShareStart(moved, pool));
        EXPECT_FALSE(raysShareStart(later, pool));
    }

    std::vector<Ray> spread;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const glm::dvec3 d = glm::abs(glm::dvec3(random.onSphere())) + glm::dvec3(0.01);
        spread.push_back(makeRay(random.vec3(-3.0f, 3.0f), d));
    }
    spread[spread.size() - 2].origin = glm::vec3(1.0f, -7.5f, 0.0f);
    std::vector<Ray> turned = spread;
    turned[turned.size() - 5] = makeRay(turned[turned.size() - 5].origin, glm::dvec3(-1.0, 0.2, 0.3));
    glm::vec3 farthest(0.0f);
    for (const Ray& r : spread) farthest = glm::max(farthest, glm::abs(r.origin));
    ASSERT_EQ(farthest.y, 7.5f);
    for (ThreadPool* pool : {static_cast<ThreadPool*>(nullptr), &two}) {
        const FrameGeometry g = frameGeometry(triangles, bounds, spread, sceneBox, 0, pool);
        EXPECT_FALSE(g.raysShareStart);
        EXPECT_TRUE(sameBytes(g.farthestOrigin, farthest));
        EXPECT_EQ(g.order, ChildOrder::NearSide);  // every ray toward high x, y and z
        EXPECT_EQ(g.nearSide, glm::vec3(-std::numeric_limits<float>::max()));
        EXPECT_EQ(g.margin, filterMargin(sceneBox, farthest));
        const FrameGeometry t = frameGeometry(triangles, bounds, turned, sceneBox, 0, pool);
        EXPECT_EQ(t.order, ChildOrder::PerRay);  // x both ways
        EXPECT_EQ(t.nearSide, glm::vec3(0.0f));
    }
}

// What the library takes on trust for a perspective camera's rays (RayBatch::Impl::pinholeRays,
// FrameGeometry::uniformByConstruction): one origin, tmin and tmax, bit for bit, whatever the
// camera, the image size or the pixel offset (antialiasing samples), as a scan finds them.
TEST(FrameScans, APerspectiveCamerasRaysShareTheirStartAndSegment) {
    Random random(20261206);
    ThreadPool two(2);
    std::vector<Ray> rays;
    for (int k = 0; k < 40; ++k) {
        Camera c;
        c.eye = random.inBox(-50.0, 50.0);
        c.forward = glm::normalize(glm::dvec3(random.onSphere()));
        glm::dvec3 upHint = glm::dvec3(random.onSphere());
        if (std::abs(glm::dot(upHint, c.forward)) > 0.99) upHint = glm::dvec3(c.forward.y, c.forward.z, c.forward.x);
        c.up = glm::normalize(upHint - glm::dot(upHint, c.forward) * c.forward);
        c.yfovRadians = random.uniform(0.1, 2.5);
        const int width = 1 + int(random.index(90)), height = 1 + int(random.index(70));
        ASSERT_TRUE(viewFrustum(c, width, height).has_value());
        primaryRays(c, width, height, two, rays, glm::dvec2(random.uniform(), random.uniform()));
        ASSERT_TRUE(raysShareStart(rays)) << "camera " << k;
        ASSERT_TRUE(raysShareSegment(rays)) << "camera " << k;
        EXPECT_EQ(rays.front().tmin, 0.0f);
        EXPECT_EQ(rays.front().tmax, kNoHitT);
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
