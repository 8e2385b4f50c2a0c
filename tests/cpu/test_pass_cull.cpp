// The pass cull (cpu/pass_cull.hpp): it never drops a triangle that the intersection test
// reports for a ray of the pass, it drops what it should, and the CPU backends trace a
// culled pass with brute force's visibility over every triangle.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/random.hpp"
#include "cpu/option_predicates.hpp"
#include "cpu/pass_cull.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

// The grid's resolution of the tests: the scenes are small, and the budget would choose one
// cell (the box of the segments).
constexpr unsigned kTestCells = 24;

PassCull cullOf(const FrameGeometry& g, const SkipSwitches& switches = {}, unsigned cells = kTestCells) {
    ThreadPool pool(2);
    PassCull cull;
    cullForPass(g, switches, pool, cull, cells);
    return cull;
}

// Whether a test accepts the pair anywhere in the ray's segment (the any-hit rule).
bool accepted(const shared::TriangleHit& h, const Ray& ray) { return h.hit && h.t > ray.tmin && h.t <= ray.tmax; }

// Every triangle that the watertight or the Moller-Trumbore test reports for a ray of the
// frame must be one the cull keeps: checked pair by pair.
::testing::AssertionResult keepsEveryHitTriangle(const FrameGeometry& g, const PassCull& cull) {
    const std::vector<Triangle>& tris = *g.triangles;
    std::vector<std::uint8_t> kept(tris.size(), cull.skips.applied ? 0 : 1);
    if (cull.skips.applied)
        for (std::uint32_t id : cull.skips.traced) kept[id] = 1;
    std::size_t dropped = 0, hitPairs = 0;
    std::string examples;
    for (std::size_t r = 0; r < g.rays->size(); ++r) {
        const Ray& ray = (*g.rays)[r];
        for (std::uint32_t p = 0; p < tris.size(); ++p) {
            const Triangle& t = tris[p];
            const bool hit = accepted(shared::intersectWatertight(ray, t.v0, t.v1, t.v2, t.cullBackFace != 0u), ray) ||
                             accepted(intersectMollerTrumbore(ray, t.v0, t.v1, t.v2, t.cullBackFace != 0u), ray);
            hitPairs += hit;
            if (!hit || kept[p]) continue;
            if (++dropped <= 3) examples += " [ray " + std::to_string(r) + ", triangle " + std::to_string(p) + "]";
        }
    }
    if (dropped) return ::testing::AssertionFailure() << dropped << " hit pairs on dropped triangles:" << examples;
    return ::testing::AssertionSuccess() << hitPairs << " hit pairs, all kept";
}

// The frame the backends trace after the cull: every ray misses where nothing is kept.
std::vector<Hit> traceCulled(const FrameGeometry& g, const PassCull& cull, Backend backend, unsigned regions) {
    if (cull.skips.applied && cull.skips.traced.empty()) {
        std::vector<Hit> misses;
        for (const Ray& ray : *g.rays) misses.push_back(missHit(ray));
        return misses;
    }
    return traceFrame(withSkips(g, cull.skips), backend, regions, 2).hits;
}

// A pass of these rays over these triangles (both outlive it), culled by the faces' tests
// alone.
struct FacesOnlyPass {
    std::vector<Bounds> bounds;
    FrameGeometry geometry;
    PassCull cull;
    FacesOnlyPass(const std::vector<Triangle>& tris, const std::vector<Ray>& rays)
        : bounds(allTriangleBounds(tris)), geometry(secondaryFrame(tris, bounds, rays, sceneBounds(tris))) {
        SkipSwitches facesOnly;
        facesOnly.passRays = false;
        cull = cullOf(geometry, facesOnly);
    }
    FacesOnlyPass(const FacesOnlyPass&) = delete;
};

// Random triangles of size `scale` in a box of side 40 scale around `shift`, single-sided one
// in two, and rays from points on them: lengths from a thousandth of a triangle to unbounded,
// directions with zero components, one shared direction where `sharedDirection`, and origins
// on the box's faces travelling along them.
struct RandomPass {
    std::vector<Triangle> triangles;
    std::vector<Bounds> bounds;
    std::vector<Ray> rays;
    FrameGeometry geometry;

    RandomPass(std::uint64_t seed, double scale, double shift, bool sharedDirection) {
        Random random(seed);
        const glm::dvec3 centre(shift, -0.5 * shift, 0.25 * shift);
        while (triangles.size() < 600) {
            const glm::dvec3 at = centre + random.inBox(-20.0, 20.0) * scale;
            Triangle t{};
            t.v0 = glm::vec3(at);
            t.v1 = glm::vec3(at + random.inBox(-1.0, 1.0) * scale);
            t.v2 = glm::vec3(at + random.inBox(-1.0, 1.0) * scale);
            t.cullBackFace = random.uniform() < 0.5 ? 1u : 0u;
            if (!shared::triangleHasNoArea(t.v0, t.v1, t.v2)) triangles.push_back(t);
        }
        bounds = allTriangleBounds(triangles);
        const Box box = sceneBounds(triangles);
        const glm::dvec3 shared = glm::normalize(random.inBox(-1.0, 1.0));
        for (int i = 0; i < 600; ++i) {
            const Triangle& t = triangles[random.index(triangles.size())];
            const float u = float(random.uniform()), v = float(random.uniform()) * (1.0f - u);
            glm::vec3 origin = t.v0 + u * (t.v1 - t.v0) + v * (t.v2 - t.v0);
            glm::dvec3 dir = sharedDirection ? shared : glm::normalize(random.inBox(-1.0, 1.0));
            if (!sharedDirection && i % 5 == 0) dir[random.index(3)] = 0.0;  // in a plane of the grid's axes
            if (!sharedDirection && i % 7 == 0) {  // on a face of the scene box, along it
                const int a = int(random.index(3));
                origin[a] = random.uniform() < 0.5 ? box.lo[a] : box.hi[a];
                dir[a] = 0.0;
            }
            if (glm::length(dir) == 0.0) dir = glm::dvec3(1, 0, 0);
            const double lengths[] = {1e-3 * scale, 0.3 * scale, 2.0 * scale, 15.0 * scale};
            const float length = i % 5 == 4 ? kNoHitT : float(lengths[i % 4]);
            rays.push_back(shared::segmentRay(origin, glm::vec3(glm::normalize(dir)), length));
        }
        geometry = secondaryFrame(triangles, bounds, rays, box);
    }
    RandomPass(const RandomPass&) = delete;
};

}  // namespace

TEST(PassCull, NeverDropsATriangleARayFromATriangleHits) {
    std::uint64_t outside = 0, backFacing = 0;
    std::uint64_t seed = 1;
    for (double scale : {1e-3, 1.0, 1e4})
        for (double shift : {0.0, 30.0, 3e4})
            for (bool sharedDirection : {false, true}) {
                SCOPED_TRACE("scale " + std::to_string(scale) + ", shift " + std::to_string(shift) +
                             (sharedDirection ? ", one direction" : ""));
                const RandomPass pass(seed++, scale, shift * scale, sharedDirection);
                for (unsigned cells : {1u, 7u, RayGrid::kMaxCells}) {
                    const PassCull cull = cullOf(pass.geometry, {}, cells);
                    EXPECT_TRUE(cull.raysTested);
                    EXPECT_EQ(cull.directionShared, sharedDirection);
                    EXPECT_TRUE(keepsEveryHitTriangle(pass.geometry, cull)) << cells << " cells";
                    outside += cull.outsideRays;
                    backFacing += cull.skips.backFacing;
                }
            }
    EXPECT_GT(outside, 0u) << "the grid dropped nothing: the test proves nothing";
    EXPECT_GT(backFacing, 0u) << "no back face dropped: the test proves nothing";
}

namespace {

// The set's passes and two directional lights' (from above, grazing), each culled and checked
// pair by pair; the triangles dropped are added up.
void expectSetKeepsEveryHitTriangle(SecondaryPassSet& set, std::uint64_t& outside, std::uint64_t& backFacing) {
    set.passes.push_back({"directional, from above", directionalShadowPass({0.2, -1.0, -0.1})});
    set.passes.push_back({"directional, grazing", directionalShadowPass({1.0, -0.05, 0.0})});
    for (const auto& [name, p] : set.passes) {
        SCOPED_TRACE(set.name + ": " + name);
        const PassFrame pass(set.frame, set.primary.hits, p);
        ASSERT_GT(pass.rays.rays.size(), 100u);
        const PassCull cull = cullOf(pass.geometry);
        EXPECT_TRUE(keepsEveryHitTriangle(pass.geometry, cull));
        outside += cull.outsideRays;
        backFacing += cull.skips.backFacing;
    }
}

}  // namespace

TEST(PassCull, NeverDropsATriangleAShadowOrOcclusionRayHits) {
    // Point lights above and among the shapes, directional lights, short and unbounded
    // occlusion rays, and a single-sided ceiling every upward ray meets from behind.
    std::uint64_t outside = 0, backFacing = 0;
    SecondaryPassSet shapes = shapesSecondaryPasses(), ceiling = shapesUnderACeilingPasses();
    expectSetKeepsEveryHitTriangle(shapes, outside, backFacing);
    expectSetKeepsEveryHitTriangle(ceiling, outside, backFacing);
    EXPECT_GT(outside, 0u);
    EXPECT_GT(backFacing, 0u);
}

TEST(PassCull, EveryCpuBackendTracesTheCulledPassWithBruteForcesVisibility) {
    SecondaryPassSet set = shapesUnderACeilingPasses();
    set.passes.push_back({"occlusion 0.3", occlusionPass(2, 0.3f)});
    set.passes.push_back({"directional", directionalShadowPass({0.2, -1.0, -0.1})});
    for (const auto& [name, p] : set.passes) {
        SCOPED_TRACE(name);
        const PassFrame pass(set.frame, set.primary.hits, p);
        const std::vector<Hit> reference = pass.trace(Backend::Brute, 0, 2).hits;
        const PassCull cull = cullOf(pass.geometry);
        ASSERT_TRUE(cull.skips.applied) << "nothing culled";
        EXPECT_TRUE(identicalVisibility(reference, traceCulled(pass.geometry, cull, Backend::Brute, 0)));
        EXPECT_TRUE(identicalVisibility(reference, traceCulled(pass.geometry, cull, Backend::CpuSeq, 0)));
        for (unsigned regions : {1u, 3u})
            EXPECT_TRUE(identicalVisibility(reference, traceCulled(pass.geometry, cull, Backend::Cpu, regions)))
                << regions << " regions";
    }
}

TEST(PassCull, EachHalfTurnsOffAlone) {
    SecondaryPassSet set = shapesUnderACeilingPasses();
    const PassFrame pass(set.frame, set.primary.hits, directionalShadowPass({0.2, -1.0, -0.1}));
    SkipSwitches noGrid, noFaces, none;
    noGrid.passRays = false;
    noFaces.backFaces = false;
    none.passRays = none.backFaces = false;
    const PassCull both = cullOf(pass.geometry), faces = cullOf(pass.geometry, noGrid), grid = cullOf(pass.geometry, noFaces);
    EXPECT_GT(both.outsideRays, 0u);
    EXPECT_GT(both.skips.backFacing, 0u);
    EXPECT_FALSE(faces.raysTested);
    EXPECT_EQ(faces.outsideRays, 0u);
    EXPECT_GT(faces.skips.backFacing, 0u);
    EXPECT_EQ(grid.skips.backFacing, 0u);
    EXPECT_EQ(grid.outsideRays, both.outsideRays);
    EXPECT_FALSE(cullOf(pass.geometry, none).skips.applied);
}

TEST(PassCull, KeepsATriangleASegmentEndingUnitsInTheLastPlaceShortOfItHits) {
    // A triangle in the plane z = 4, on a boundary of the grid's cells (the box is [0, 8]^3, 8
    // cells), and segments from far below whose float ends fall a few units in the last place
    // of their length short of it: the watertight test still accepts some, whose exact
    // segments end in the cell below the triangle's. Only the margin keeps the triangle.
    std::vector<Triangle> tris(3);
    tris[0] = Triangle{{1, 1, 4}, 0, {7, 1, 4}, 0, {4, 7, 4}, 0};
    tris[1] = Triangle{{0, 0, 0}, 0, {0.1f, 0, 0}, 0, {0, 0.1f, 0}, 0};
    tris[2] = Triangle{{8, 8, 8}, 0, {7.9f, 8, 8}, 0, {8, 7.9f, 8}, 0};
    const std::vector<Bounds> bounds = allTriangleBounds(tris);
    Random random(5);
    std::size_t short_ = 0;
    ThreadPool pool(1);
    PassCull cull;
    for (double depth : {10.0, 1000.0}) {
        for (int i = 0; i < 400; ++i) {
            const glm::vec3 origin(float(random.uniform(3.0, 5.0)), float(random.uniform(3.0, 5.0)), float(4.0 - depth));
            const glm::vec3 dir(glm::normalize(glm::dvec3(random.uniform(-1e-3, 1e-3), random.uniform(-1e-3, 1e-3), 1.0)));
            const double exact = (4.0 - double(origin.z)) / double(dir.z);
            float tmax = float(exact);
            for (int k = 0; k < i % 8; ++k) tmax = std::nextafter(tmax, 0.0f);
            const std::vector<Ray> rays{shared::segmentRay(origin, dir, tmax)};
            const Ray& ray = rays.front();
            const shared::TriangleHit h = shared::intersectWatertight(ray, tris[0].v0, tris[0].v1, tris[0].v2, false);
            short_ += accepted(h, ray) && double(ray.tmax) * double(ray.dir.z) + double(origin.z) < 4.0;
            // Each segment alone: no other marks the triangle's cells.
            const FrameGeometry g = secondaryFrame(tris, bounds, rays, sceneBounds(tris));
            cullForPass(g, {}, pool, cull, 8);
            ASSERT_TRUE(keepsEveryHitTriangle(g, cull)) << "from " << depth << " below, ray " << i;
        }
    }
    EXPECT_GT(short_, 0u) << "no accepted hit lies beyond its segment's exact end: the test proves nothing";
}

TEST(PassCull, KeepsASingleSidedTriangleNearlyAlongTheSharedDirectionThatRoundingShowsFront) {
    // Triangles tilted by 1e-9 to 1e-1 of their size out of a plane holding the rays' shared
    // direction d, to their back (n . d > 0, exactly), and a ray along d through each
    // centroid: rounding makes the watertight test see some from the front and accept them.
    // Only the margin of facesAwayAlong keeps those.
    Random random(9);
    const glm::vec3 d(glm::normalize(glm::dvec3(0.3, -0.8, 0.5)));
    const glm::dvec3 dd(d);
    const glm::dvec3 u = glm::normalize(glm::cross(dd, glm::dvec3(1, 0, 0))), w = glm::cross(dd, u);
    std::vector<Triangle> tris;
    std::vector<Ray> rays;
    std::size_t frontByRounding = 0;
    for (int i = 0; i < 600; ++i) {
        const double size = std::pow(10.0, random.uniform(-2.0, 3.0));
        const double tilt = std::pow(10.0, random.uniform(-9.0, -1.0));
        const glm::dvec3 a = random.inBox(-1.0, 1.0) * 100.0;
        const Triangle t{glm::vec3(a), 1, glm::vec3(a + u * size), 0, glm::vec3(a + (dd + w * tilt) * size), 0};
        const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
        if (!(glm::dot(glm::cross(p1 - p0, p2 - p0), dd) > 0.0)) continue;  // float rounding flipped it: not a back face
        const glm::vec3 centroid = (t.v0 + t.v1 + t.v2) / 3.0f;
        const Ray ray = shared::segmentRay(centroid - d * float(2.0 * size), d, kNoHitT);
        frontByRounding += accepted(shared::intersectWatertight(ray, t.v0, t.v1, t.v2, true), ray);
        tris.push_back(t);
        rays.push_back(ray);
    }
    const FacesOnlyPass pass(tris, rays);
    const FrameGeometry& g = pass.geometry;
    const PassCull& cull = pass.cull;
    ASSERT_TRUE(cull.directionShared);
    EXPECT_GT(cull.skips.backFacing, 0u) << "no triangle tilted enough to drop";
    EXPECT_TRUE(keepsEveryHitTriangle(g, cull));
    EXPECT_GT(frontByRounding, 0u) << "rounding never showed a back face from the front: the test proves nothing";
}

TEST(PassCull, KeepsASingleSidedTriangleNearlyEdgeOnToTheSharedEndThatRoundingShowsFront) {
    // Triangles tilted by 1e-9 to 1e-1 of their size out of a plane through a point light
    // L, to show their front to it (n . (L - v0) > 0, exactly), and a shadow ray to L from far
    // beyond each, through its centroid, made as a pass makes one (the direction L - origin
    // rounded, the segment ending at t = 1): every ray meets a back face in exact arithmetic,
    // and rounding makes the watertight test see some from the front and accept them, among
    // them triangles whose plane passes the light by far more than the spread of the rays'
    // ends. Only the margin of facesTowardEnds keeps those.
    Random random(10);
    const glm::vec3 light(3.0f, 40.0f, -7.0f);
    const glm::dvec3 l(light);
    std::vector<Triangle> tris;
    std::vector<Ray> rays;
    std::size_t frontByRounding = 0;
    for (int i = 0; i < 2000; ++i) {
        // One in four large and tilted enough for the margin, with a near origin: the drops.
        const bool large = i % 4 == 0;
        const double size = std::pow(10.0, large ? random.uniform(1.0, 2.0) : random.uniform(-3.0, 0.0));
        const double tilt = std::pow(10.0, large ? random.uniform(-2.0, -0.5) : random.uniform(-9.0, -1.0));
        const glm::dvec3 a = random.inBox(-1.0, 1.0) * 30.0;
        const glm::dvec3 toLight = glm::normalize(l - a), u = glm::normalize(glm::cross(toLight, random.inBox(-1.0, 1.0)));
        const glm::dvec3 w = glm::cross(toLight, u);
        // v0 = a, v1 along u, v2 toward the light tilted along w: n = u x (toLight + w tilt) =
        // tilt toLight - w, so n . (L - a) = tilt |L - a| > 0: its front faces L.
        const Triangle t{glm::vec3(a), 1, glm::vec3(a + u * size), 0, glm::vec3(a + (toLight + w * tilt) * size), 0};
        const glm::dvec3 p0(t.v0), p1(t.v1), p2(t.v2);
        const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
        if (!(glm::dot(n, l - p0) > 0.0)) continue;  // float rounding turned it: not a front to the light
        const glm::dvec3 centroid = (p0 + p1 + p2) / 3.0;
        const glm::vec3 origin(centroid + (centroid - l) * (large ? random.uniform(0.05, 0.5) : random.uniform(1.0, 30.0)));
        const Ray ray = shared::segmentRay(origin, light - origin, 1.0f);
        // The rays' ends spread by about 1e-4 (a unit in the last place of 1500): a plane 1e-2
        // from the light leaves all of them on its front.
        frontByRounding += accepted(shared::intersectWatertight(ray, t.v0, t.v1, t.v2, true), ray) &&
                           glm::dot(n, l - p0) / glm::length(n) > 1e-2;
        tris.push_back(t);
        rays.push_back(ray);
    }
    const FacesOnlyPass pass(tris, rays);
    const FrameGeometry& g = pass.geometry;
    const PassCull& cull = pass.cull;
    ASSERT_FALSE(cull.directionShared);
    ASSERT_TRUE(cull.endShared);
    EXPECT_GT(cull.skips.backFacing, 0u) << "no triangle tilted enough to drop";
    EXPECT_TRUE(keepsEveryHitTriangle(g, cull));
    EXPECT_GT(frontByRounding, 0u) << "rounding never showed a back face well off the light from the front: the test "
                                      "proves nothing";
}

TEST(PassCull, SharesNoEndWhereTheSegmentsEndApartOrAreWhole) {
    // A triangle above a point light, facing down to it, and rays from below toward the light:
    // segments that end at the light never reach it (it is dropped), but one ray of a longer
    // segment, or rays that do not end, pass the light and hit its front. Occlusion rays of one
    // length end apart.
    const glm::vec3 light(0.0f, 10.0f, 0.0f);
    const std::vector<Triangle> tris{Triangle{{-5, 12, -5}, 1, {5, 12, -5}, 0, {0, 12, 5}, 0}};
    ASSERT_GT(glm::dot(glm::cross(glm::dvec3(tris[0].v1 - tris[0].v0), glm::dvec3(tris[0].v2 - tris[0].v0)),
                       glm::dvec3(light - tris[0].v0)),
              0.0)
        << "the triangle shows its front to the light";
    auto toLight = [&](float tmaxOfTheLast) {
        std::vector<Ray> rays;
        for (int i = 0; i < 50; ++i) {
            const glm::vec3 origin(float(i % 7) - 3.0f, 0.0f, float(i % 5) - 2.0f);
            rays.push_back(shared::segmentRay(origin, light - origin, i == 49 ? tmaxOfTheLast : 1.0f));
        }
        return rays;
    };
    {
        const std::vector<Ray> rays = toLight(1.0f);
        const FacesOnlyPass pass(tris, rays);
        EXPECT_TRUE(pass.cull.endShared);
        EXPECT_EQ(pass.cull.skips.backFacing, 1u);
        EXPECT_TRUE(keepsEveryHitTriangle(pass.geometry, pass.cull));
    }
    for (float tmax : {2.5f, kNoHitT}) {
        const std::vector<Ray> rays = toLight(tmax);
        const FacesOnlyPass pass(tris, rays);
        EXPECT_FALSE(pass.cull.endShared) << "the last ray ends at " << tmax;
        EXPECT_TRUE(keepsEveryHitTriangle(pass.geometry, pass.cull)) << "the last ray ends at " << tmax;
    }
    std::vector<Ray> whole = toLight(kNoHitT);
    for (Ray& r : whole) r = shared::segmentRay(r.origin, r.dir, kNoHitT);
    const FacesOnlyPass wholeRays(tris, whole);
    EXPECT_FALSE(wholeRays.cull.endShared) << "rays that do not end";
    EXPECT_TRUE(keepsEveryHitTriangle(wholeRays.geometry, wholeRays.cull));

    SecondaryPassSet set = shapesUnderACeilingPasses();
    SkipSwitches facesOnly;
    facesOnly.passRays = false;
    for (const SecondaryPass& p : {occlusionPass(2, 0.3f), occlusionPass(2, kNoHitT)}) {
        const PassFrame pass(set.frame, set.primary.hits, p);
        const PassCull cull = cullOf(pass.geometry, facesOnly);
        EXPECT_FALSE(cull.endShared);
        EXPECT_FALSE(cull.skips.applied);
    }
}

namespace {

// The survey of rays as a pass's groups make them: the rays cut at `cuts` (ascending), each
// piece surveyed ray by ray, then the pieces merged in order (an empty piece among them).
RaySurvey surveyInPieces(const std::vector<Ray>& rays, std::vector<std::size_t> cuts) {
    cuts.insert(cuts.begin(), 0);
    cuts.push_back(rays.size());
    RaySurvey whole;
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
        RaySurvey piece;
        for (std::size_t i = cuts[c]; i < cuts[c + 1]; ++i) piece.add(rays[i]);
        whole.merge(piece);
    }
    return whole;
}

// cullFromSurvey's verdicts against cullForPass's over the same rays with the grid off: the
// same tests decided, the same triangles kept, in the same order.
void expectSurveyGivesTheScansCull(const FrameGeometry& g, const SkipSwitches& switches) {
    ThreadPool pool(2);
    PassCull scanned, surveyed;
    cullForPass(g, switches, pool, scanned);
    const std::vector<Ray>& rays = *g.rays;
    for (const std::vector<std::size_t>& cuts :
         {std::vector<std::size_t>{}, {rays.size() / 7, rays.size() / 7, rays.size() * 4 / 7}, {1}, {rays.size()}}) {
        cullFromSurvey(g, surveyInPieces(rays, cuts), switches, pool, surveyed);
        EXPECT_EQ(surveyed.directionShared, scanned.directionShared);
        EXPECT_EQ(surveyed.endShared, scanned.endShared);
        EXPECT_FALSE(surveyed.raysTested);
        EXPECT_EQ(surveyed.skips.applied, scanned.skips.applied);
        EXPECT_EQ(surveyed.skips.backFacing, scanned.skips.backFacing);
        EXPECT_EQ(surveyed.skips.traced, scanned.skips.traced);
    }
}

}  // namespace

TEST(PassCull, ASurveyTakenAsTheRaysAreMadeGivesTheScansVerdicts) {
    // The passes of both sets and two directional lights (a shared direction), point lights
    // (a shared end), occlusion rays (neither), with the back-face test on and off.
    SkipSwitches facesOnly, none;
    facesOnly.passRays = false;
    none.passRays = none.backFaces = false;
    std::size_t shared = 0, dropped = 0;
    SecondaryPassSet shapes = shapesSecondaryPasses(), ceiling = shapesUnderACeilingPasses();
    for (SecondaryPassSet* set : {&shapes, &ceiling}) {
        set->passes.push_back({"directional, from above", directionalShadowPass({0.2, -1.0, -0.1})});
        set->passes.push_back({"directional, grazing", directionalShadowPass({1.0, -0.05, 0.0})});
        for (const auto& [name, p] : set->passes) {
            SCOPED_TRACE(set->name + ": " + name);
            const PassFrame pass(set->frame, set->primary.hits, p);
            ASSERT_GT(pass.rays.rays.size(), 10u);
            expectSurveyGivesTheScansCull(pass.geometry, facesOnly);
            expectSurveyGivesTheScansCull(pass.geometry, none);
            const PassCull cull = cullOf(pass.geometry, facesOnly);
            shared += cull.directionShared || cull.endShared;
            dropped += cull.skips.backFacing;
        }
    }
    EXPECT_GT(shared, 0u);
    EXPECT_GT(dropped, 0u) << "no back face dropped: the comparison proves little";
    // Segments that end at one light but one (a longer segment, or a whole ray), and ends one
    // spread apart: the survey must refuse the shared end where the scan does.
    const glm::vec3 light(0.0f, 10.0f, 0.0f);
    const std::vector<Triangle> tris{Triangle{{-5, 12, -5}, 1, {5, 12, -5}, 0, {0, 12, 5}, 0}};
    for (float tmaxOfOne : {1.0f, 1.0f + 0x1p-20f, 2.5f, kNoHitT}) {
        for (std::size_t odd : {std::size_t(0), std::size_t(25), std::size_t(49)}) {
            SCOPED_TRACE("ray " + std::to_string(odd) + " ends at t = " + std::to_string(tmaxOfOne));
            std::vector<Ray> rays;
            for (std::size_t i = 0; i < 50; ++i) {
                const glm::vec3 origin(float(i % 7) - 3.0f, 0.0f, float(i % 5) - 2.0f);
                rays.push_back(shared::segmentRay(origin, light - origin, i == odd ? tmaxOfOne : 1.0f));
            }
            const FacesOnlyPass pass(tris, rays);
            expectSurveyGivesTheScansCull(pass.geometry, facesOnly);
        }
    }
}

TEST(PassCull, FacesTowardEndsAsksEveryPointOfTheEndBox) {
    // n = (1, 1, 1): a box whose centre lies in front of the plane x + y + z = 0 but whose
    // lowest corner lies behind it keeps the triangle; a box wholly in front drops it.
    const Triangle t{{0, 0, 0}, 1, {1, -1, 0}, 0, {1, 0, -1}, 0};
    EXPECT_TRUE(facesTowardEnds(t, glm::dvec3(0.5), glm::dvec3(1.0), 4.0));
    EXPECT_FALSE(facesTowardEnds(t, glm::dvec3(-0.6), glm::dvec3(1.0), 4.0));
    EXPECT_FALSE(facesTowardEnds(t, glm::dvec3(-1.0), glm::dvec3(-0.5), 4.0)) << "behind it";
    EXPECT_FALSE(facesTowardEnds(t, glm::dvec3(0.5), glm::dvec3(1.0), 1e9)) << "a reach the margin cannot clear";
}

TEST(PassCull, TestsNothingOnlyWhereItsCheapCheckSaysSo) {
    // passCullTests spares a pass its geometry; where it says no, the full cull must drop
    // nothing and test nothing, on every pass of the test sets.
    SecondaryPassSet shapes = shapesSecondaryPasses(), ceiling = shapesUnderACeilingPasses();
    ThreadPool pool(2);
    std::size_t spared = 0, tested = 0;
    for (SecondaryPassSet* set : {&shapes, &ceiling}) {
        set->passes.push_back({"directional", directionalShadowPass({0.2, -1.0, -0.1})});
        for (const auto& [name, p] : set->passes) {
            SCOPED_TRACE(set->name + ": " + name);
            const PassFrame pass(set->frame, set->primary.hits, p);
            const std::vector<Ray>& rays = *pass.geometry.rays;
            for (const SkipSwitches& switches : {SkipSwitches{}, SkipSwitches{.passRays = false}}) {
                PassCull cull;
                cullForPass(pass.geometry, switches, pool, cull);
                if (passCullTests(rays, pass.geometry.triangles->size(), pass.geometry.sceneBox, switches)) {
                    ++tested;
                    continue;
                }
                ++spared;
                EXPECT_FALSE(cull.raysTested || cull.directionShared || cull.endShared || cull.skips.applied);
            }
        }
    }
    EXPECT_GT(spared, 0u);
    EXPECT_GT(tested, 0u);
}
