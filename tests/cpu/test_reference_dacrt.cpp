// The reference DACRT (cpu/reference_dacrt.hpp) against brute force, and the optimised cpu
// backends (cpu-seq with and without packets, SIMD and scalar paths; cpu with several regions,
// threads and axes) against the reference, bit for bit, on random and adversarial scenes.
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/random.hpp"
#include "cpu/reference_dacrt.hpp"
#include "cpu/traversal.hpp"
#include "support/frames.hpp"
#include "support/tight_box_scene.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

// Triangles and rays, traced as one frame.
struct Case {
    std::vector<Triangle> triangles;
    std::vector<Ray> rays;
    std::uint32_t imageWidth = 0;  // nonzero: the rays are an image's pixels (packets)
    HitQuery query = HitQuery::Closest;
};

Triangle triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, bool singleSided = false) {
    return Triangle{a, singleSided ? 1u : 0u, b, 0.0f, c, 0.0f};
}

void append(std::vector<Triangle>& to, const Mesh& mesh) {
    const Scene s = sceneFromMeshes({mesh});
    to.insert(to.end(), s.triangles.begin(), s.triangles.end());
}

bool sameBits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

// Closest hit: primitive, t, u and v bit for bit. Any hit: the visibility bit (the hit itself
// may be any in the segment).
::testing::AssertionResult sameHits(const std::vector<Hit>& expected, const std::vector<Hit>& actual, HitQuery query) {
    if (expected.size() != actual.size()) return ::testing::AssertionFailure() << "sizes differ";
    std::size_t differing = 0;
    std::string first;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        const Hit &e = expected[i], &a = actual[i];
        const bool same = query == HitQuery::Any ? (e.prim == kMissPrim) == (a.prim == kMissPrim)
                                                 : e.prim == a.prim && sameBits(e.t, a.t) && sameBits(e.u, a.u) &&
                                                       sameBits(e.v, a.v);
        if (!same && ++differing == 1)
            first = "ray " + std::to_string(i) + ": prim " + std::to_string(e.prim) + " t " + std::to_string(e.t) +
                    " vs prim " + std::to_string(a.prim) + " t " + std::to_string(a.t);
    }
    if (differing) return ::testing::AssertionFailure() << differing << " rays differ, first " << first;
    return ::testing::AssertionSuccess();
}

// An any-hit answer must be a real hit of its ray inside the segment: the leaf test's own
// result for that triangle.
::testing::AssertionResult genuineHits(const FrameGeometry& g, const std::vector<Hit>& hits) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
        if (hits[i].prim == kMissPrim) continue;
        const Ray& ray = (*g.rays)[i];
        Hit alone = missHit(ray);
        testTriangle(ray, (*g.triangles)[hits[i].prim], hits[i].prim, alone);
        if (alone.prim != hits[i].prim || !sameBits(alone.t, hits[i].t))
            return ::testing::AssertionFailure() << "ray " << i << " reports prim " << hits[i].prim << " at t "
                                                 << hits[i].t << ", which that triangle's test does not give";
    }
    return ::testing::AssertionSuccess();
}

// The optimised traversal's option sets that promise brute force's hits: the defaults (SIMD,
// packets where the rays allow), without packets, packets down to the leaves, and the scalar
// path (the exact separating-axis filter) with the smallest leaves; each again with the
// ray-sampling cost deciding leaves and splits (where the tiny leaves leave it every node).
std::vector<std::pair<std::string, DacrtOptions>> exactOptionSets() {
    DacrtOptions noPackets, packetsToTheLeaves, scalarTinyLeaves, noTightBoxes;
    noPackets.packets = false;
    packetsToTheLeaves.packetFlush = 1;
    scalarTinyLeaves.triangleFilter = TriangleFilter::Sat;
    scalarTinyLeaves.rayLimit = 1;
    scalarTinyLeaves.triLimit = 2;
    noTightBoxes.tightBoxes = false;
    std::vector<std::pair<std::string, DacrtOptions>> sets = {{"defaults", {}},
                                                              {"no packets", noPackets},
                                                              {"packets to the leaves", packetsToTheLeaves},
                                                              {"scalar, tiny leaves", scalarTinyLeaves},
                                                              {"no tight boxes", noTightBoxes}};
    for (std::size_t i = 0, n = sets.size(); i < n; ++i) {
        DacrtOptions sampled = sets[i].second;
        sampled.splitCost = SplitCost::RaySampling;
        sets.emplace_back(sets[i].first + ", ray-sampling cost", sampled);
    }
    return sets;
}

void expectExact(const Case& c) {
    const std::vector<Bounds> bounds = allTriangleBounds(c.triangles);
    FrameGeometry g = frameGeometry(c.triangles, bounds, c.rays, sceneBounds(c.triangles), c.imageWidth);
    g.query = c.query;
    ThreadPool twoThreads(2);
    const std::vector<Hit> brute = traceBrute(g, twoThreads).hits;
    ASSERT_GT(hitCount(brute), 0u) << "the case should hit something";
    ASSERT_LT(hitCount(brute), brute.size()) << "the case should miss somewhere";

    const std::vector<Hit> reference = traceReferenceDacrt(g);
    EXPECT_TRUE(sameHits(brute, reference, c.query)) << "reference vs brute force";
    for (const ReferenceLeafLimits limits : {ReferenceLeafLimits{1, 1, 24}, ReferenceLeafLimits{64, 64, 48}})
        EXPECT_TRUE(sameHits(brute, traceReferenceDacrt(g, limits), c.query))
            << "reference with leaves below " << limits.rays << " rays, " << limits.triangles << " triangles";
    if (c.query == HitQuery::Any) {
        EXPECT_TRUE(genuineHits(g, reference)) << "reference";
    }

    auto check = [&](const std::vector<Hit>& hits, const std::string& what) {
        EXPECT_TRUE(sameHits(reference, hits, c.query)) << what << " vs reference";
        if (c.query == HitQuery::Any) {
            EXPECT_TRUE(genuineHits(g, hits)) << what;
        }
    };
    for (const auto& [name, options] : exactOptionSets()) check(traceSequential(g, options).hits, "cpu-seq, " + name);
    for (unsigned threads : {1u, 2u}) {
        ThreadPool pool(threads);
        TraceOptions o;
        for (unsigned regions : {1u, 2u, 5u, 8u}) {
            o.regions = regions;
            check(traceParallel(g, o, pool).hits,
                  "cpu, " + std::to_string(regions) + " regions, " + std::to_string(threads) + " threads");
        }
        o.regions = 3;
        for (DivisionAxis axis : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z}) {
            o.axis = axis;
            check(traceParallel(g, o, pool).hits, "cpu, 3 regions along axis " + std::to_string(int(axis) - 1) +
                                                      ", " + std::to_string(threads) + " threads");
        }
        o.axis = DivisionAxis::Best;
        o.dacrt.packets = false;
        check(traceParallel(g, o, pool).hits, "cpu, 3 regions, no packets, " + std::to_string(threads) + " threads");
        o.dacrt.splitCost = SplitCost::RaySampling;
        check(traceParallel(g, o, pool).hits, "cpu, 3 regions, no packets, ray-sampling cost, " + std::to_string(threads) + " threads");
        o.dacrt.packets = true;
        check(traceParallel(g, o, pool).hits, "cpu, 3 regions, ray-sampling cost, " + std::to_string(threads) + " threads");
    }
}

// `count` random triangles of about `size` in [-1, 1]^3, every third single-sided, and every
// seventh followed by a coincident copy (a tie the ids break) and a coplanar overlapping one.
std::vector<Triangle> randomSoup(std::uint64_t seed, int count, float size) {
    Random random(seed);
    std::vector<Triangle> tris;
    for (int i = 0; i < count; ++i) {
        const glm::vec3 c = random.vec3(-1.0f, 1.0f);
        const Triangle t = triangle(c + random.vec3(-size, size), c + random.vec3(-size, size),
                                    c + random.vec3(-size, size), i % 3 == 0);
        tris.push_back(t);
        if (i % 7 != 0) continue;
        tris.push_back(t);
        tris.push_back(triangle(t.v0, 0.5f * (t.v0 + t.v1), t.v2));
    }
    return tris;
}

// A perspective camera at `eye` looking at `target`: the rays share their start (packets).
std::vector<Ray> cameraRays(glm::dvec3 eye, int width, int height, glm::dvec3 target = glm::dvec3(0.0)) {
    Camera c;
    c.eye = eye;
    c.forward = glm::normalize(target - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(c.forward, glm::dvec3(0, 1, 0)));
    c.up = glm::cross(right, c.forward);
    c.yfovRadians = 0.9;
    return primaryRays(c, width, height);
}

// Rays from random origins in [-reach, reach]^3 in random directions: no common near side.
std::vector<Ray> randomRays(std::uint64_t seed, int count, float reach) {
    Random random(seed);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) rays.push_back(makeRay(random.vec3(-reach, reach), random.onSphere()));
    return rays;
}

std::vector<Triangle> scaled(std::vector<Triangle> tris, float s) {
    for (Triangle& t : tris) {
        t.v0 *= s;
        t.v1 *= s;
        t.v2 *= s;
    }
    return tris;
}

}  // namespace

TEST(ReferenceDacrt, RandomSoupsFromACamera) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Case c{randomSoup(seed, 300, 0.25f), cameraRays({0.3 * double(seed), 0.8, 3.0}, 48, 40), 48};
        expectExact(c);
    }
}

TEST(ReferenceDacrt, RandomSoupsAndRaysFromManyOrigins) {
    for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
        for (std::uint64_t seed : {4u, 5u}) {
            SCOPED_TRACE("seed " + std::to_string(seed) + (query == HitQuery::Any ? ", any hit" : ", closest"));
            Case c{randomSoup(seed, 300, 0.2f), randomRays(seed + 100, 2000, 1.5f)};
            c.query = query;
            expectExact(c);
        }
    }
}

TEST(ReferenceDacrt, ProceduralShapesFromInsideAndOutside) {
    const Scene shapes = shapesScene();
    for (const glm::dvec3 eye : {glm::dvec3(0.5, 1.5, 4.0), glm::dvec3(0.1, -0.3, 0.2)}) {
        SCOPED_TRACE("eye " + std::to_string(eye.x) + " " + std::to_string(eye.y) + " " + std::to_string(eye.z));
        expectExact(Case{shapes.triangles, cameraRays(eye, 40, 30), 40});
    }
    Case c{shapes.triangles, randomRays(9, 2000, 2.0f)};
    expectExact(c);
}

TEST(ReferenceDacrt, CoincidentAndCoplanarTrianglesTieByIdEverywhere) {
    // The plane z = 0 three times over: two identical grids and one shifted by half a cell.
    std::vector<Triangle> tris;
    append(tris, grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 6, 6));
    append(tris, grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 6, 6));
    append(tris, grid({-0.8f, -0.8f, 0}, {2, 0, 0}, {0, 2, 0}, 6, 6));
    append(tris, box({-0.3f, -0.3f, -0.5f}, {0.3f, 0.3f, 0.5f}));  // pierces the planes
    expectExact(Case{tris, cameraRays({0.2, 0.4, 2.5}, 40, 40), 40});
    Case below{tris, cameraRays({-0.1, -0.3, -2.0}, 40, 40), 40};
    expectExact(below);
    expectExact(Case{tris, randomRays(11, 2000, 1.5f)});
}

TEST(ReferenceDacrt, SharedEdgesAndVerticesHitExactly) {
    // A grid whose vertices are multiples of 1/4 and rays straight down through every vertex,
    // edge midpoint and cell centre (multiples of 1/8): each hits an edge or a vertex exactly
    // (or a diagonal), where two to six triangles meet. Many origins, one direction.
    std::vector<Triangle> tris;
    append(tris, grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 8, 8));
    append(tris, grid({-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, 4, 4));  // a floor below, for the misses
    std::vector<Ray> down, fromAPoint;
    for (int i = -9; i <= 9; ++i)
        for (int j = -9; j <= 9; ++j) {
            const glm::vec3 target(float(i) / 8.0f, float(j) / 8.0f, 0.0f);
            down.push_back(makeRay(target + glm::vec3(0, 0, 1), {0, 0, -1}));
            fromAPoint.push_back(makeRay({0.0f, 0.0f, 2.0f}, glm::dvec3(target) - glm::dvec3(0, 0, 2)));
        }
    down.push_back(makeRay({0, 0, 1}, {0, 0, 1}));  // away from everything
    expectExact(Case{tris, down});
    expectExact(Case{tris, fromAPoint});
}

TEST(ReferenceDacrt, RaysAlongSplitPlanesAndAxisAlignedTriangles) {
    // The scene box [-2, 2] x [-1, 1] x [-1, 1]: the first splits are x = 0, then x = -1 and
    // x = 1, then y = 0 and z = 0. Triangles lie in those planes, and rays travel inside them.
    std::vector<Triangle> tris;
    append(tris, box({-2, -1, -1}, {2, 1, 1}));
    append(tris, doubleSided(grid({0, -0.5f, -0.5f}, {0, 1, 0}, {0, 0, 1}, 2, 2)));  // in x = 0
    append(tris, doubleSided(grid({-1.5f, 0, -0.5f}, {1, 0, 0}, {0, 0, 1}, 2, 2)));  // in y = 0
    append(tris, doubleSided(grid({0.5f, -0.5f, 0}, {1, 0, 0}, {0, 1, 0}, 2, 2)));  // in z = 0
    tris.push_back(triangle({1, -0.25f, -0.25f}, {1, 0.25f, -0.25f}, {1, 0, 0.25f}));  // in x = 1
    std::vector<Ray> rays;
    for (int i = 0; i < 16; ++i) {
        const float s = -0.9f + 0.12f * float(i);
        const double a = 0.4 * double(i);
        rays.push_back(makeRay({0, s, -0.95f}, {0, std::sin(a), std::cos(a)}));  // inside x = 0
        rays.push_back(makeRay({-1.9f, 0, s}, {std::cos(a), 0, std::sin(a)}));  // inside y = 0
        rays.push_back(makeRay({s, 0.1f, 0}, {std::sin(a), std::cos(a), 0}));  // inside z = 0
        rays.push_back(makeRay({1, s, 0}, {0, -std::cos(a), std::sin(a)}));  // inside x = 1
        rays.push_back(makeRay({0, 0, 0}, {std::cos(a), std::sin(a), 0.3}));  // from the splits' crossing
        rays.push_back(makeRay({-1.9f, s, 0.2f}, {1, 0, 0}));  // along x, across every x split
        rays.push_back(makeRay({1.9f, 0.2f, s}, {-1, 0, 0}));  // and back
    }
    expectExact(Case{tris, rays});
    Case any{tris, rays};
    any.query = HitQuery::Any;
    expectExact(any);
    // A camera where the splits x = 0, y = 0 and z = 0 cross.
    expectExact(Case{tris, cameraRays({0.0, 0.0, 0.0}, 32, 32, {1.0, 0.1, 0.1}), 32});
}

TEST(ReferenceDacrt, NearlyCoincidentWallsAcrossASplitPlane) {
    // Two walls one float step either side of x = 1, a split of the scene, seen obliquely: the
    // watertight test's rounding of t exceeds the gap, so the far wall wins some pixels by t or
    // by id, and a cell must still have tested it: what the filter margin guarantees
    // (docs/correctness.md; test_tracers.cpp's case of the same name).
    const float below = std::nextafter(1.0f, 0.0f), above = std::nextafter(1.0f, 2.0f);
    const std::vector<Mesh> meshes = {doubleSided(grid({below, -4, -4}, {0, 8, 0}, {0, 0, 8}, 9, 7)),
                                      doubleSided(grid({above, -4, -4}, {0, 8, 0}, {0, 0, 8}, 7, 9)),
                                      grid({0, -4, -4}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1),
                                      grid({2, 3.9f, 3.9f}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1)};
    CameraOptions o;
    o.eye = glm::dvec3(0.3, 0.1, 0.2);
    o.target = glm::dvec3(1.0, 1.5, -2.0);
    o.fovDegrees = 100.0;
    const Frame frame(sceneFromMeshes(meshes), 160, 120, o);
    expectExact(Case{frame.scene.triangles, frame.rays, 160});
}

TEST(ReferenceDacrt, TinyAndHugeCoordinates) {
    const std::vector<Triangle> soup = randomSoup(21, 250, 0.25f);
    for (float scale : {1e-6f, 1e8f}) {
        SCOPED_TRACE("scale " + std::to_string(scale));
        std::vector<Ray> rays = randomRays(22, 1500, 1.5f);
        for (Ray& r : rays) r = makeRay(r.origin * scale, glm::dvec3(r.dir));
        expectExact(Case{scaled(soup, scale), rays});
        expectExact(Case{scaled(soup, scale), cameraRays(glm::dvec3(0.4, 0.7, 3.0) * double(scale), 32, 32), 32});
    }
}

TEST(ReferenceDacrt, SegmentsEndingBeforeOnAndAfterTheirHits) {
    // Segments of random length, and segments ending exactly at brute force's hit of the whole
    // ray (a hit at tmax counts) or one float before it (it does not), some starting late.
    const std::vector<Triangle> soup = randomSoup(31, 300, 0.2f);
    const std::vector<Bounds> bounds = allTriangleBounds(soup);
    std::vector<Ray> rays = randomRays(32, 2000, 1.5f);
    const FrameGeometry whole = frameGeometry(soup, bounds, rays, sceneBounds(soup));
    ThreadPool pool(2);
    const std::vector<Hit> full = traceBrute(whole, pool).hits;
    Random random(33);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const float t = full[i].t;
        switch (i % 4) {
            case 0: rays[i].tmax = random.uniformFloat(0.05f, 3.0f); break;
            case 1: rays[i].tmax = full[i].prim == kMissPrim ? 1.0f : t; break;
            case 2: rays[i].tmax = full[i].prim == kMissPrim ? 2.0f : std::nextafter(t, 0.0f); break;
            default:
                rays[i].tmin = random.uniformFloat(0.0f, 1.0f);
                rays[i].tmax = rays[i].tmin + random.uniformFloat(0.1f, 1.0f);
        }
    }
    for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
        SCOPED_TRACE(query == HitQuery::Any ? "any hit" : "closest");
        Case c{soup, rays};
        c.query = query;
        expectExact(c);
    }
}

TEST(ReferenceDacrt, TightBoxesKeepTheHitsOnTheirTrianglesBounds) {
    // Clusters far apart, rays at and along their bounds' faces (support/tight_box_scene.hpp),
    // closest and any hit, and a camera's rays; the counters show that the boxes shrank
    // (DacrtTraversal::tightenedBox) and saved tests.
    const TightBoxScene scene = tightBoxScene();
    std::vector<Triangle> tris;
    for (const Mesh& m : scene.meshes) append(tris, m);
    const std::vector<Ray>& rays = scene.rays;
    // A camera's rays as well, whose packets shrink their nodes' boxes too.
    std::vector<Case> cases = {Case{tris, rays}, Case{tris, rays}, Case{tris, cameraRays(scene.cameraEye, 64, 64), 64}};
    cases[1].query = HitQuery::Any;
    for (const Case& c : cases) {
        SCOPED_TRACE(c.imageWidth ? "camera" : c.query == HitQuery::Any ? "any hit" : "closest");
        expectExact(c);
        const std::vector<Bounds> bounds = allTriangleBounds(c.triangles);
        FrameGeometry g = frameGeometry(c.triangles, bounds, c.rays, sceneBounds(c.triangles), c.imageWidth);
        g.query = c.query;
        DacrtOptions scalar;
        for (const auto& [name, options] : exactOptionSets())
            if (name == "scalar, tiny leaves") scalar = options;
        ASSERT_EQ(scalar.triangleFilter, TriangleFilter::Sat) << "the scalar path's option set was renamed";
        for (const DacrtOptions& on : {DacrtOptions{}, scalar}) {
            DacrtOptions without = on;
            without.tightBoxes = false;
            const Counters tight = traceSequential(g, on).counters, loose = traceSequential(g, without).counters;
            EXPECT_GT(tight.tightBoxes, 0u);
            EXPECT_EQ(loose.tightBoxes, 0u);
            EXPECT_LT(tight.rayTriangleTests, loose.rayTriangleTests);
        }
    }
}
