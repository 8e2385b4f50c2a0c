// The face rule (single-sided triangles are hit from the front only) in every CPU test, and
// the triangle skips: each drops only triangles no ray of the frame can hit, so every backend
// traces the same hits with them as brute force does without them.
#include <cstring>

#include <gtest/gtest.h>

#include "core/procedural.hpp"
#include "core/random.hpp"
#include "cpu/option_predicates.hpp"
#include "cpu/traversal.hpp"
#include "cpu/triangle_skips.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

Triangle triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, bool cullBackFace) {
    Triangle t{};
    t.v0 = a;
    t.v1 = b;
    t.v2 = c;
    t.cullBackFace = cullBackFace ? 1u : 0u;
    return t;
}

// Whether each CPU test of the leaf hits `t` along ray.
struct LeafHits {
    bool watertight, mollerTrumbore, float64;
};
LeafHits leafHits(const Ray& ray, const Triangle& t) {
    Hit a = missHit(), b = missHit(), c = missHit();
    testTriangle(ray, t, 0, a);
    testTriangleMollerTrumbore(ray, t, 0, b);
    testTriangleF64(toF64(ray), t, 0, c);
    return {a.prim == 0, b.prim == 0, c.prim == 0};
}

// A camera inside a closed box whose faces point outward (every wall shows its back), looking
// at a sphere and a torus (which show their fronts), another sphere behind it: the
// open-mesh-from-inside case.
Scene insideOutScene(CullMode cull) {
    Scene s = sceneFromMeshes({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2),
                               torus({-1.0f, -0.5f, -2.5f}, 0.6f, 0.2f, 24, 12),
                               icosphere({0.0f, 0.0f, 2.5f}, 0.5f, 1)});  // behind the camera
    applyCullMode(s, cull);
    return s;
}

CameraOptions insideCamera() {
    CameraOptions o;
    o.eye = glm::dvec3(0.1, 0.05, 0.2);
    o.target = glm::dvec3(0.0, -0.2, -1.0);
    o.fovDegrees = 70.0;
    return o;
}

// The frame traced with the skips `switches` allow, as the dispatcher does.
TraceResult traceWithSkips(const Frame& frame, Backend backend, const SkipSwitches& switches, unsigned regions = 2) {
    ThreadPool pool(2);
    const TriangleSkips skips = skipTriangles(frame.geometry, switches, pool);
    TraceOptions o;
    o.backend = backend;
    o.regions = regions;
    o.threads = 2;
    return traceCpu(withSkips(frame.geometry, skips), o, pool);
}

}  // namespace

TEST(FaceRule, SingleSidedTrianglesAreHitFromTheFrontOnly) {
    // Counter-clockwise seen from +z, so its front faces +z.
    const Ray fromFront = makeRay({0.1f, 0.1f, 1.0f}, {0.0, 0.0, -1.0});
    const Ray fromBack = makeRay({0.1f, 0.1f, -1.0f}, {0.0, 0.0, 1.0});
    const glm::vec3 a{-1, -1, 0}, b{1, -1, 0}, c{0, 1, 0};
    for (bool cull : {false, true}) {
        const LeafHits front = leafHits(fromFront, triangle(a, b, c, cull));
        const LeafHits back = leafHits(fromBack, triangle(a, b, c, cull));
        EXPECT_TRUE(front.watertight && front.mollerTrumbore && front.float64) << "cull " << cull;
        EXPECT_EQ(back.watertight, !cull);
        EXPECT_EQ(back.mollerTrumbore, !cull);
        EXPECT_EQ(back.float64, !cull);
    }
    // The same triangle wound the other way faces -z.
    EXPECT_FALSE(leafHits(fromFront, triangle(a, c, b, true)).watertight);
    EXPECT_TRUE(leafHits(fromBack, triangle(a, c, b, true)).watertight);
}

TEST(FaceRule, AppliesToTheWholeSceneOnlyWhereTheMaterialSaysSo) {
    Scene s = insideOutScene(CullMode::Material);
    EXPECT_EQ(singleSidedTriangles(s.triangles), s.triangles.size()) << "glTF's default material is single-sided";
    s.materials[s.materialOfTriangle.front()].doubleSided = true;
    applyCullMode(s, CullMode::Material);
    EXPECT_LT(singleSidedTriangles(s.triangles), s.triangles.size());
    applyCullMode(s, CullMode::None);
    EXPECT_EQ(singleSidedTriangles(s.triangles), 0u);
    applyCullMode(s, CullMode::BackFaces);
    EXPECT_EQ(singleSidedTriangles(s.triangles), s.triangles.size());
}

TEST(Skips, ABackFacingDropIsNeverATriangleARayFromTheOriginHits) {
    // Triangles at every distance and slant, nearly edge-on ones included, and rays from the
    // origin through their corners, edges and inside: whatever facesAwayFrom drops, no CPU
    // test hits under the face rule.
    Random rng(7);
    int dropped = 0, nearlyEdgeOn = 0;
    for (int i = 0; i < 40000; ++i) {
        const glm::vec3 origin = rng.vec3(-2.0f, 2.0f);
        const double distance = std::pow(10.0, rng.uniform(-1.0, 3.0));
        const glm::dvec3 centre = glm::dvec3(origin) + distance * glm::normalize(rng.inBox(-1.0, 1.0) + 1e-9);
        const double size = distance * std::pow(10.0, rng.uniform(-5.0, 0.0));
        glm::dvec3 p[3];
        for (glm::dvec3& q : p) q = centre + size * rng.inBox(-1.0, 1.0);
        if (i % 2 == 0) {  // flatten toward the plane through the origin: nearly edge-on
            const glm::dvec3 n = glm::normalize(glm::cross(centre - glm::dvec3(origin), p[1] - p[0]));
            const double squeeze = std::pow(10.0, rng.uniform(-8.0, -2.0));
            for (glm::dvec3& q : p) q -= (1.0 - squeeze) * glm::dot(q - glm::dvec3(origin), n) * n;
        }
        const Triangle t = triangle(glm::vec3(p[0]), glm::vec3(p[1]), glm::vec3(p[2]), true);
        if (!facesAwayFrom(t, glm::dvec3(origin))) continue;
        ++dropped;
        nearlyEdgeOn += i % 2 == 0;
        for (int k = 0; k < 16; ++k) {
            double w[3] = {rng.uniform(), rng.uniform(), rng.uniform()};
            if (k < 3) w[0] = w[1] = w[2] = 0.0, w[k] = 1.0;                     // a corner
            if (k >= 3 && k < 6) w[k - 3] = 0.0;                                // an edge
            const double sum = w[0] + w[1] + w[2];
            const glm::dvec3 target = (w[0] * glm::dvec3(t.v0) + w[1] * glm::dvec3(t.v1) + w[2] * glm::dvec3(t.v2)) / sum;
            if (glm::length(target - glm::dvec3(origin)) == 0.0) continue;
            const LeafHits h = leafHits(makeRay(origin, target - glm::dvec3(origin)), t);
            ASSERT_FALSE(h.watertight || h.mollerTrumbore || h.float64) << "triangle " << i << ", ray " << k;
        }
    }
    EXPECT_GT(dropped, 6000);
    EXPECT_GT(nearlyEdgeOn, 250);
}

TEST(Skips, AFrustumDropIsNeverATriangleAPrimaryRayHits) {
    // Double-sided triangles scattered around the view's edges, many straddling them: brute
    // force over every triangle never reports one that outsideFrustum drops.
    Random rng(11);
    Camera camera;
    camera.eye = glm::dvec3(0.3, -0.2, 4.0);
    camera.forward = glm::normalize(glm::dvec3(0.1, 0.05, -1.0));
    camera.up = glm::normalize(glm::cross(glm::cross(camera.forward, glm::dvec3(0, 1, 0)), camera.forward));
    camera.yfovRadians = glm::radians(50.0);
    const int w = 48, h = 32;
    const ViewFrustum f = *viewFrustum(camera, w, h);
    const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
    std::vector<Triangle> tris;
    for (int i = 0; i < 3000; ++i) {
        // A point on a frustum edge at some depth, a triangle about it.
        const double depth = std::pow(10.0, rng.uniform(-1.0, 2.0));
        const double y = std::tan(0.5 * camera.yfovRadians), x = y * w / h;
        const double sx = i % 2 ? (rng.uniform() < 0.5 ? -x : x) : rng.uniform(-x, x);
        const double sy = i % 2 ? rng.uniform(-y, y) : (rng.uniform() < 0.5 ? -y : y);
        const glm::dvec3 c = camera.eye + depth * (camera.forward + sx * right + sy * camera.up);
        const double size = depth * std::pow(10.0, rng.uniform(-4.0, -1.0));
        tris.push_back(triangle(glm::vec3(c + size * rng.inBox(-1, 1)), glm::vec3(c + size * rng.inBox(-1, 1)),
                                glm::vec3(c + size * rng.inBox(-1, 1)), false));
    }
    std::vector<bool> outside(tris.size());
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < tris.size(); ++i) dropped += outside[i] = outsideFrustum(tris[i], f);
    EXPECT_GT(dropped, 200u);
    EXPECT_LT(dropped, tris.size() - 300);
    // Rays through the pixels' corners as well as their centres: the frustum bounds them all.
    for (const glm::dvec2 offset : {glm::dvec2(0.5, 0.5), glm::dvec2(0.0, 0.0), glm::dvec2(1.0, 1.0), glm::dvec2(0.0, 1.0)}) {
        const std::vector<Ray> rays = primaryRays(camera, w, h, offset);
        for (const Ray& r : rays)
            for (std::size_t i = 0; i < tris.size(); ++i) {
                if (!outside[i]) continue;
                Hit best = missHit();
                testTriangle(r, tris[i], std::uint32_t(i), best);
                ASSERT_EQ(best.prim, kMissPrim) << "triangle " << i << " dropped but hit";
            }
    }
}

TEST(Skips, EveryCpuBackendWithSkipsEqualsBruteWithoutInsideAnOpenBox) {
    Frame culled(insideOutScene(CullMode::Material), 64, 48, insideCamera());
    const Frame unculled(insideOutScene(CullMode::None), 64, 48, insideCamera());
    ThreadPool pool(2);
    SkipSwitches none;
    none.backFaces = none.frustum = false;
    // traceWithSkips passes regions, so cpu runs the parallel scheme whatever the frame's size.
    const TraceResult reference = traceWithSkips(culled, Backend::Brute, none);
    // The rule changes the image: the walls behind the shapes are back faces.
    EXPECT_LT(hitCount(reference.hits), hitCount(traceWithSkips(unculled, Backend::Brute, none).hits));
    EXPECT_GT(hitCount(reference.hits), 100u);
    culled.geometry.frustum = viewFrustum(defaultCamera(culled.scene, 64, 48, insideCamera()), 64, 48);
    const TriangleSkips skips = skipTriangles(culled.geometry, SkipSwitches{}, pool);
    EXPECT_TRUE(skips.applied);
    EXPECT_GT(skips.backFacing, 12u) << "the box's walls";
    EXPECT_GT(skips.outsideFrustum, 0u) << "the sphere behind the camera";
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu})
        for (unsigned regions : {1u, 2u, 4u})
            EXPECT_TRUE(identicalHits(reference.hits, traceWithSkips(culled, b, SkipSwitches{}, regions).hits))
                << toString(b) << ", " << regions << " regions";
}

// The skip pass's list and box are their scalar definitions, bit for bit: the ids of the
// triangles neither test drops, ascending, and the box Box::extend makes of their vertices in
// that order (the first of equal values wins, so a zero's sign is the first zero's). A sphere of
// 20,480 single-sided triangles (five chunks of the pass) touches x = 0 and y = 0, where its
// vertices take +0 or -0 at random; half its faces turn away from the eye, and a narrow view
// leaves part of it outside the frustum.
TEST(Skips, TheTracedListAndBoxAreTheirScalarDefinitionsBitForBit) {
    Scene scene = sceneFromMeshes({icosphere({0.5f, -0.5f, -3.0f}, 0.5f, 5)});
    applyCullMode(scene, CullMode::BackFaces);
    Random rng(41);
    std::size_t signedZeros = 0;
    for (Triangle& t : scene.triangles)
        for (glm::vec3* v : {&t.v0, &t.v1, &t.v2}) {
            if (v->x <= 0.02f) v->x = rng.uniform() < 0.5 ? -0.0f : 0.0f, ++signedZeros;
            if (v->y >= -0.02f) v->y = rng.uniform() < 0.5 ? -0.0f : 0.0f, ++signedZeros;
        }
    ASSERT_GT(signedZeros, 20u);
    CameraOptions view;
    view.eye = glm::dvec3(2.0, -0.7, 0.0);
    view.target = glm::dvec3(0.5, -0.5, -3.0);
    view.fovDegrees = 6.0;
    Frame frame(std::move(scene), 64, 48, view);
    frame.geometry.frustum = viewFrustum(defaultCamera(frame.scene, 64, 48, view), 64, 48);
    ThreadPool pool(2);
    for (const bool frustum : {false, true}) {
        SkipSwitches switches;
        switches.frustum = frustum;
        const TriangleSkips skips = skipTriangles(frame.geometry, switches, pool);
        ASSERT_TRUE(skips.applied);
        ASSERT_EQ(skips.frustumTested, frustum);
        std::vector<std::uint32_t> traced;
        Box box;
        std::uint64_t back = 0, outside = 0;
        const glm::dvec3 origin(frame.geometry.rayOrigin);
        for (std::uint32_t i = 0; i < frame.scene.triangles.size(); ++i) {
            const Triangle& t = frame.scene.triangles[i];
            if (t.cullBackFace && facesAwayFrom(t, origin)) {
                ++back;
            } else if (frustum && outsideFrustum(t, *frame.geometry.frustum)) {
                ++outside;
            } else {
                traced.push_back(i);
                box.extend(t.v0), box.extend(t.v1), box.extend(t.v2);
            }
        }
        EXPECT_GT(back, 8000u);
        if (frustum) EXPECT_GT(outside, 1000u);
        EXPECT_EQ(skips.backFacing, back);
        EXPECT_EQ(skips.outsideFrustum, outside);
        ASSERT_EQ(std::vector<std::uint32_t>(skips.traced.begin(), skips.traced.end()), traced) << "frustum " << frustum;
        EXPECT_EQ(std::memcmp(&skips.tracedBox, &box, sizeof(Box)), 0)
            << "frustum " << frustum << ": lo " << skips.tracedBox.lo.x << " " << skips.tracedBox.lo.y << ", expected "
            << box.lo.x << " " << box.lo.y << "; hi " << skips.tracedBox.hi.x << " " << skips.tracedBox.hi.y
            << ", expected " << box.hi.x << " " << box.hi.y;
        if (!frustum) EXPECT_TRUE(box.lo.x == 0.0f && box.hi.y == 0.0f) << "the zeros must bound the traced box";
    }
}

TEST(Skips, AFrameWhoseTrianglesAreAllSkippedNeedsNoTrace) {
    // Looking away from everything: the skips leave no triangle.
    CameraOptions o;
    o.eye = glm::dvec3(0.0, 0.0, 10.0);
    o.target = glm::dvec3(0.0, 0.0, 20.0);
    Frame frame(test::shapesScene(), 32, 24, o);
    frame.geometry.frustum = viewFrustum(defaultCamera(frame.scene, 32, 24, o), 32, 24);
    ThreadPool pool(1);
    const TriangleSkips skips = skipTriangles(frame.geometry, SkipSwitches{}, pool);
    EXPECT_TRUE(skips.applied);
    EXPECT_TRUE(skips.traced.empty());
    EXPECT_EQ(skips.outsideFrustum + skips.backFacing, frame.scene.triangles.size());
}
