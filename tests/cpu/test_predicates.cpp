// The shared predicates (shaders/predicates.glsl compiled as C++).
#include <cmath>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "core/procedural.hpp"
#include "core/random.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/predicates.hpp"
#include "cpu/trace_result.hpp"
#include "core/shader_layout.hpp"

using namespace dacrt;

namespace {

// Exact slab interval in double precision for a float ray (the reference the widened float
// interval must contain).
bool exactInterval(const Ray& r, const glm::vec3& lo, const glm::vec3& hi, double& tNear, double& tFar) {
    tNear = -1e300;
    tFar = 1e300;
    for (int a = 0; a < 3; ++a) {
        if (r.dir[a] == 0.0f) {
            if (r.origin[a] < lo[a] || r.origin[a] > hi[a]) return false;
            continue;
        }
        double t0 = (double(lo[a]) - r.origin[a]) / r.dir[a], t1 = (double(hi[a]) - r.origin[a]) / r.dir[a];
        if (t0 > t1) std::swap(t0, t1);
        tNear = std::max(tNear, t0);
        tFar = std::min(tFar, t1);
    }
    return tNear <= tFar;
}

}  // namespace

TEST(RayBoxInterval, ContainsTheExactIntervalOnRandomRays) {
    Random rng(7);
    int checked = 0;
    for (int i = 0; i < 200000; ++i) {
        const glm::vec3 lo = rng.vec3(-100.0f, 100.0f), hi = lo + glm::abs(rng.vec3(-100.0f, 100.0f));
        glm::dvec3 d = rng.vec3(-1.0f, 1.0f);
        if (i % 7 == 0) d[i % 3] = 0.0;  // axis-parallel rays too
        if (glm::length(d) == 0.0) continue;
        const Ray r = makeRay(rng.vec3(-100.0f, 100.0f), d);
        double tNear, tFar;
        const shared::RayInterval iv = shared::rayBoxInterval(r, lo, hi);
        ASSERT_FALSE(std::isnan(iv.tNear) || std::isnan(iv.tFar));
        if (!exactInterval(r, lo, hi, tNear, tFar)) continue;
        ++checked;
        ASSERT_LE(double(iv.tNear), tNear) << "ray " << i;
        ASSERT_GE(double(iv.tFar), tFar) << "ray " << i;
    }
    EXPECT_GT(checked, 1000);
}

TEST(RayMayCrossCell, TheWidenedCellKeepsEveryRayOfTheCell) {
    // The filters rely on the margin, not on widened t bounds: with the margin of the frame,
    // a ray that truly crosses the cell (within [tmin, tmax]) must pass the filter.
    Random rng(11);
    int crossing = 0;
    for (int i = 0; i < 200000; ++i) {
        const glm::vec3 origin = rng.vec3(-1000.0f, 1000.0f);
        const glm::vec3 lo = rng.vec3(-1000.0f, 1000.0f), hi = lo + glm::abs(rng.vec3(-1.0f, 1.0f)) * 50.0f;
        Box scene;
        scene.extend(lo);
        scene.extend(hi);
        const float margin = filterMargin(scene, origin);
        // Aim at a point of the box, often on a face or an edge (grazing rays).
        glm::dvec3 target;
        for (int a = 0; a < 3; ++a) {
            const float f = rng.uniformFloat(0.0f, 1.0f);
            target[a] = f < 0.2f ? lo[a] : (f > 0.8f ? hi[a] : lo[a] + (hi[a] - lo[a]) * double(rng.uniformFloat(0.0f, 1.0f)));
        }
        glm::dvec3 d = target - glm::dvec3(origin);
        if (i % 5 == 0) d[i % 3] = 0.0;
        if (glm::length(d) == 0.0) continue;
        const Ray r = makeRay(origin, d);
        double tNear, tFar;
        if (!exactInterval(r, lo, hi, tNear, tFar) || tFar < 0.0) continue;
        ++crossing;
        const float tmax = float(std::max(tNear, 0.0)) * (1.0f + 1e-7f);
        ASSERT_TRUE(shared::rayMayCrossCell(r, lo - glm::vec3(margin), hi + glm::vec3(margin), std::max(tmax, 0.0f)))
            << "ray " << i;
    }
    EXPECT_GT(crossing, 1000);
}

TEST(RayBoxInterval, ZeroDirectionOnTheBoundaryIsDefined) {
    const Ray r = makeRay({1.0f, 0.5f, -5.0f}, {0.0, 0.0, 1.0});
    const shared::RayInterval on = shared::rayBoxInterval(r, {0, 0, 0}, {1, 1, 1});  // origin x on the face
    EXPECT_LE(on.tNear, 5.0f);
    EXPECT_GE(on.tFar, 6.0f);
    const shared::RayInterval off = shared::rayBoxInterval(r, {1.5f, 0, 0}, {2, 1, 1});
    EXPECT_GT(off.tNear, off.tFar);
    EXPECT_FALSE(shared::rayMayCrossCell(r, {1.5f, 0, 0}, {2, 1, 1}, kNoHitT));
}

TEST(Watertight, RaysThroughSharedEdgesAndVerticesAlwaysHit) {
    // A fan of triangles around a shared vertex: rays aimed exactly at the shared vertex and
    // at points on the shared edges must hit at least one triangle.
    const int n = 7;
    std::vector<Triangle> fan;
    for (int k = 0; k < n; ++k) {
        const double a0 = 2 * M_PI * k / n, a1 = 2 * M_PI * ((k + 1) % n) / n;
        Triangle t{};
        t.v0 = {0.1f, -0.2f, 0.3f};
        t.v1 = glm::vec3(0.1 + std::cos(a0), -0.2 + std::sin(a0), 0.3);
        t.v2 = glm::vec3(0.1 + std::cos(a1), -0.2 + std::sin(a1), 0.3);
        fan.push_back(t);
    }
    Random rng(3);
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 origin = rng.vec3(-3.0f, 3.0f) + glm::vec3(0.0f, 0.0f, 4.0f);
        const Triangle& t = fan[std::size_t(i % n)];
        const glm::vec3 target = i % 2 ? t.v0 : t.v0 + rng.uniformFloat(0.0f, 1.0f) * (t.v1 - t.v0);
        const Ray r = makeRay(origin, glm::dvec3(target) - glm::dvec3(origin));
        bool hit = false;
        for (const Triangle& f : fan) hit |= shared::intersectWatertight(r, f.v0, f.v1, f.v2, false).hit;
        ASSERT_TRUE(hit) << "ray " << i << " leaked through the fan";
    }
}

TEST(Watertight, DegenerateTrianglesNeverHitAndNeverGiveNaN) {
    const Ray r = makeRay({0.2f, 0.2f, 5.0f}, {0.0, 0.0, -1.0});
    const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    for (const auto& [p, q, s] : std::vector<std::array<glm::vec3, 3>>{{a, a, a}, {a, b, b}, {a, b, 0.5f * (a + b)}}) {
        const shared::TriangleHit h = shared::intersectWatertight(r, p, q, s, false);
        EXPECT_FALSE(h.hit);
        EXPECT_FALSE(std::isnan(h.t));
    }
    const shared::TriangleHit h = shared::intersectWatertight(r, a, b, c, false);
    ASSERT_TRUE(h.hit);
    EXPECT_FLOAT_EQ(h.t, 5.0f);
    EXPECT_FLOAT_EQ(h.u, 0.2f);
    EXPECT_FLOAT_EQ(h.v, 0.2f);
}

// A zero-area triangle (three collinear vertices in float32) on the very line of the ray:
// the sign test passes on rounding residues, the ray really meets the segment, so only the
// degenerate-triangle rule keeps it from being hit. Found by a search over random rays aimed
// at such segments; removing triangleHasNoArea from intersectWatertight makes this fail.
TEST(Watertight, AZeroAreaTriangleOnTheRaysLineIsNeverHit) {
    const glm::vec3 origin{0x1.88db66p-4f, 0x1.b89234p-8f, 0x1.4p+2f};
    const glm::vec3 p0{-0x1.6865dp-2f, -0x1.855a4p-4f, 0x1.83117cp-1f};
    const glm::vec3 p1{-0x1.7edc1ap-2f, -0x1.99c564p-4f, 0x1.18a442p-1f};
    const glm::vec3 p2{-0x1.880e0ap-2f, -0x1.a2212cp-4f, 0x1.da265p-2f};
    const Ray ray = makeRay(origin, glm::dvec3(p0) - glm::dvec3(origin));
    EXPECT_TRUE(shared::triangleHasNoArea(p0, p1, p2));
    EXPECT_FALSE(shared::intersectWatertight(ray, p0, p1, p2, false).hit);
}

// The defect found on a scanned mesh: a sliver one unit in the last place wide, seen end-on
// from the default front view, "hit" by a ray that passes about 10 units away (the edge values
// are tiny multiples of one another and their rounding passes the sign test). It has area, so
// the degenerate rule does not apply; the projected-box rule rejects it. Brute force reported
// such hits, and every DACRT backend, which never brings that ray and that triangle together,
// missed them.
TEST(Watertight, AnEndOnSliverFarFromTheRayIsNeverHit) {
    const Scene s = sceneFromMeshes({box({-20, -20, -1}, {20, 20, 1})});
    CameraOptions view;
    view.eye = glm::dvec3(0, 16.0109, 60.4142);
    view.target = glm::dvec3(0, 16.0109, 59.4142);
    view.fovDegrees = 45;
    const std::vector<Ray> rays = primaryRays(makeCameras(s, sceneBounds(s.triangles), view, 160.0 / 120.0)[0], 160, 120);
    const glm::vec3 p0{0x1.91c3p+3f, 0x1.10341p+2f, 0x1.0cdff8p-1f};
    const glm::vec3 p1{0x1.91c302p+3f, 0x1.10341p+2f, 0x1.1a03fp-3f};
    const glm::vec3 p2{0x1.91c3p+3f, 0x1.10341p+2f, -0x1.6e537p-4f};
    EXPECT_FALSE(shared::triangleHasNoArea(p0, p1, p2));
    EXPECT_FALSE(shared::intersectWatertight(rays[4848], p0, p1, p2, false).hit);
}

// The same search at scale: segments along the view axis (x and y shared exactly, zero area)
// and slivers one unit in the last place off them, across a whole image. A hit is allowed only
// where the ray passes through the triangle's bounds (up to rounding), never far away.
TEST(Watertight, EndOnSegmentsAndSliversAreHitOnlyWhereTheRayMeetsThem) {
    const Scene s = sceneFromMeshes({box({-20, -20, -1}, {20, 20, 1})});
    CameraOptions view;
    view.eye = glm::dvec3(0, 16.0109, 60.4142);
    view.target = glm::dvec3(0, 16.0109, 59.4142);
    view.fovDegrees = 45;
    const std::vector<Ray> rays = primaryRays(makeCameras(s, sceneBounds(s.triangles), view, 4.0 / 3.0)[0], 80, 60);
    Random random(12);
    std::size_t zeroAreaHits = 0, farHits = 0, slivers = 0;
    for (int i = 0; i < 3000; ++i) {
        const float x = random.uniformFloat(-20.0f, 20.0f), y = random.uniformFloat(-20.0f, 20.0f);
        const glm::vec3 p0{x, y, random.uniformFloat(-1.0f, 1.0f)};
        glm::vec3 p1{x, y, random.uniformFloat(-1.0f, 1.0f)};
        const glm::vec3 p2{x, y, random.uniformFloat(-1.0f, 1.0f)};
        if (i % 2) p1.x = std::nextafter(p1.x, 100.0f);
        const bool noArea = shared::triangleHasNoArea(p0, p1, p2);
        slivers += !noArea;
        const glm::vec3 lo = glm::min(p0, glm::min(p1, p2)), hi = glm::max(p0, glm::max(p1, p2));
        for (const Ray& r : rays) {
            const shared::TriangleHit h = shared::intersectWatertight(r, p0, p1, p2, false);
            if (!h.hit) continue;
            zeroAreaHits += noArea;
            const glm::dvec3 at = glm::dvec3(r.origin) + double(h.t) * glm::dvec3(r.dir);
            const glm::dvec3 outside = glm::max(glm::max(glm::dvec3(lo) - at, at - glm::dvec3(hi)), glm::dvec3(0.0));
            farHits += glm::length(outside) > 1e-3;
        }
    }
    EXPECT_GT(slivers, 1000u);
    EXPECT_EQ(zeroAreaHits, 0u);
    EXPECT_EQ(farHits, 0u);
}

TEST(TieRule, SmallerTWinsThenSmallerPrimitive) {
    EXPECT_TRUE(shared::hitPrecedes(1.0f, 9, 2.0f, 0));
    EXPECT_TRUE(shared::hitPrecedes(1.0f, 3, 1.0f, 4));
    EXPECT_FALSE(shared::hitPrecedes(1.0f, 4, 1.0f, 3));
    EXPECT_FALSE(shared::hitPrecedes(1.0f, 4, 1.0f, 4));
    EXPECT_TRUE(shared::hitPrecedes(kNoHitT, 0, kNoHitT, kMissPrim));
}

TEST(MakeRay, CanonicalisesDirections) {
    const Ray r = makeRay({0, 0, 0}, {1e-35, 0.0, -2.0});
    EXPECT_EQ(r.dir.x, 0.0f);  // below 2^-64 after normalisation
    EXPECT_EQ(r.dir.z, -1.0f);
    EXPECT_EQ(r.invDir.x, 0.0f);
    EXPECT_EQ(r.invDir.z, -1.0f);
    EXPECT_EQ((r.axes >> 4) & 3u, 2u);
    EXPECT_THROW(makeRay({0, 0, 0}, {0.0, 0.0, 0.0}), std::exception);
    EXPECT_THROW(makeRay({0, 0, 0}, {NAN, 0.0, 1.0}), std::exception);
}
