// Known answers on tiny scenes, and brute / cpu-seq / cpu agreeing bit for bit.
#include <algorithm>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/procedural.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/image_bands.hpp"
#include "cpu/traversal.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

const Backend kAllBackends[] = {Backend::Brute, Backend::CpuSeq, Backend::Cpu};

// Every backend (and every region and thread count of cpu) against brute force.
void expectAllBackendsAgree(const Frame& frame, std::initializer_list<unsigned> regionCounts,
                            DivisionAxis axis = DivisionAxis::Best) {
    const TraceResult reference = frame.trace(Backend::Brute, 0, 2);
    ASSERT_GT(hitCount(reference.hits), frame.rays.size() / 20) << "the view should show the scene";
    EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::CpuSeq).hits)) << "cpu-seq";
    DacrtOptions noPackets, packetsToTheLeaves;
    noPackets.packets = false;
    packetsToTheLeaves.packetFlush = 1;  // packets never flushed early: the packet filter everywhere
    EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::CpuSeq, 0, 1, axis, noPackets).hits))
        << "cpu-seq without packets";
    EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::CpuSeq, 0, 1, axis, packetsToTheLeaves).hits))
        << "cpu-seq with packets down to the leaves";
    EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::Cpu, 2, 2, axis, packetsToTheLeaves).hits))
        << "cpu with packets down to the leaves";
    for (unsigned regions : regionCounts)
        for (unsigned threads : {1u, 2u})
            EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::Cpu, regions, threads, axis).hits))
                << "cpu, " << regions << " regions, " << threads << " threads";
}

}  // namespace

TEST(KnownAnswers, CentreRayHitsTheSharedDiagonalAndTheTieGoesToTheSmallerId) {
    Scene s = loadGltf(fixture("quad_u8_camera.gltf"));
    const Camera cam = defaultCamera(s, 1, 1);  // the file's camera: (0,0,4) looking down -z
    const Frame frame(std::move(s), cam, 1, 1);
    for (Backend b : kAllBackends) {
        const Hit h = frame.trace(b, 2).hits[0];
        EXPECT_EQ(h.prim, 0u) << toString(b);  // (0,0) is on the edge both triangles share
        EXPECT_EQ(h.t, 4.0f) << toString(b);
    }
}

TEST(KnownAnswers, CoincidentTrianglesGoToTheSmallerIdAndNearerWins) {
    std::vector<Mesh> meshes(5, grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 1, 1));
    meshes[3] = grid({-1, -1, 0.5f}, {2, 0, 0}, {0, 2, 0}, 1, 1);  // nearer, ids 6 and 7, left half only
    meshes[3].positions[1].x = 0.0f;
    meshes[3].positions[3].x = 0.0f;
    Scene s = sceneFromMeshes(meshes);
    CameraOptions o;
    o.eye = glm::dvec3(0.0, 0.0, 5.0);
    o.target = glm::dvec3(0.0, 0.0, 0.0);
    o.fovDegrees = 20.0;
    const Frame frame(std::move(s), 16, 16, o);
    for (Backend b : kAllBackends) {
        const std::vector<Hit> hits = frame.trace(b, 3).hits;
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const Hit& h = hits[std::size_t(y * 16 + x)];
                ASSERT_NE(h.prim, kMissPrim);
                if (x < 8) EXPECT_TRUE(h.prim == 6 || h.prim == 7) << toString(b) << " pixel " << x << "," << y;
                else EXPECT_LE(h.prim, 1u) << toString(b) << " pixel " << x << "," << y;  // five coincident quads
            }
    }
}

TEST(KnownAnswers, ZeroAreaTrianglesNeverHit) {
    Mesh quad = grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 1, 1);
    Mesh sliver;  // in front of the quad, covering it, but with zero area
    sliver.positions = {{-2, -2, 1}, {2, 2, 1}, {0, 0, 1}};
    sliver.indices = {0, 1, 2};
    Scene s = sceneFromMeshes({sliver, quad});
    CameraOptions o;
    o.eye = glm::dvec3(0.0, 0.0, 5.0);
    o.target = glm::dvec3(0.0, 0.0, 0.0);
    o.fovDegrees = 15.0;
    const Frame frame(std::move(s), 12, 12, o);
    for (Backend b : kAllBackends) {
        const std::vector<Hit> hits = frame.trace(b, 2).hits;
        for (const Hit& h : hits) {
            EXPECT_TRUE(h.prim == 1 || h.prim == 2) << toString(b);
            EXPECT_FALSE(std::isnan(h.t));
        }
    }
}

TEST(BackendsAgree, ProceduralShapesFromTheFront) {
    const Scene s = test::shapesScene();
    const Frame frame(test::shapesScene(), defaultCamera(s, 96, 72), 96, 72);
    expectAllBackendsAgree(frame, {1, 2, 3, 4, 8});
}

TEST(BackendsAgree, ProceduralShapesOrbit) {
    const Scene s = test::shapesScene();
    CameraOptions o;
    o.orbit = 5;
    const std::vector<Camera> cams = makeCameras(s, sceneBounds(s.triangles), o, 4.0 / 3.0);
    for (std::size_t k = 1; k < cams.size(); ++k) {
        SCOPED_TRACE("orbit camera " + std::to_string(k));
        const Frame frame(test::shapesScene(), cams[k], 64, 48);
        expectAllBackendsAgree(frame, {2, 4, 8});
    }
}

TEST(BackendsAgree, CameraInsideTheScene) {
    // A closed box around the camera: every ray must hit, in every backend.
    std::vector<Mesh> meshes = {doubleSided(box({-3, -2, -4}, {3, 2, 4})), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2),
                                torus({-1.0f, -0.5f, 1.5f}, 0.6f, 0.2f, 24, 12)};
    CameraOptions o;
    o.eye = glm::dvec3(0.1, 0.05, 0.2);
    o.target = glm::dvec3(0.3, 0.0, -1.0);
    o.fovDegrees = 100.0;
    Scene s = sceneFromMeshes(meshes);
    const Frame frame(std::move(s), 64, 48, o);
    const TraceResult brute = frame.trace(Backend::Brute, 0, 2);
    EXPECT_EQ(hitCount(brute.hits), frame.rays.size());
    expectAllBackendsAgree(frame, {1, 2, 3, 4, 8});
    o.target = glm::dvec3(0.1, 0.05, 5.0);  // looking the other way along z
    const Frame back(sceneFromMeshes(meshes), defaultCamera(s, 64, 48, o), 64, 48);
    expectAllBackendsAgree(back, {2, 4});
}

TEST(BackendsAgree, CameraExactlyOnSplitPlanes) {
    // Scene bounds are symmetric in x and y, so x = 0 and y = 0 are the first split of both
    // the region division and the DACRT's spatial median; the camera sits on both planes.
    std::vector<Mesh> meshes = {grid({-2, -2, -1}, {4, 0, 0}, {0, 4, 0}, 8, 8), icosphere({-1, 0, 0}, 0.5f, 2),
                                icosphere({1, 0, 0}, 0.5f, 2), box({-0.25f, -0.25f, -0.5f}, {0.25f, 0.25f, 0.5f})};
    const Scene s = sceneFromMeshes(meshes);
    ASSERT_EQ(sceneBounds(s.triangles).center().x, 0.0f);
    for (const glm::dvec3& eye : {glm::dvec3(0.0, 0.0, 4.0), glm::dvec3(0.0, 0.0, 0.75)}) {
        CameraOptions o;
        o.eye = eye;
        o.target = glm::dvec3(0.0, 0.0, -1.0);
        o.fovDegrees = 90.0;
        for (DivisionAxis axis : {DivisionAxis::X, DivisionAxis::Y}) {
            SCOPED_TRACE("eye z " + std::to_string(eye.z) + ", axis " + toString(axis));
            const Frame frame(sceneFromMeshes(meshes), defaultCamera(s, 64, 64, o), 64, 64);
            expectAllBackendsAgree(frame, {2, 4}, axis);
        }
    }
}

TEST(BackendsAgree, StanfordBunnySmall) {
    DACRT_REQUIRE_SHARED_SCENE(path, "bunny.glb");
    Scene s = loadGltf(path);
    const Camera cam = defaultCamera(s, 64, 48);
    const Frame frame(std::move(s), cam, 64, 48);
    expectAllBackendsAgree(frame, {1, 2, 3, 4, 8});
}

// Packets filter the top of the recursion: fewer ray tests, the same hits.
TEST(Packets, TakeOverTheTopOfTheRecursionWithTheSameHits) {
    const Scene s = test::shapesScene();
    const Frame frame(test::shapesScene(), defaultCamera(s, 160, 120), 160, 120);
    DacrtOptions off;
    off.packets = false;
    const TraceResult without = frame.trace(Backend::CpuSeq, 0, 1, DivisionAxis::Best, off);
    const TraceResult with = frame.trace(Backend::CpuSeq);
    EXPECT_TRUE(identicalHits(without.hits, with.hits));
    EXPECT_EQ(without.counters.packetBoxTests, 0u);
    EXPECT_GT(with.counters.packetBoxTests, 0u);
    EXPECT_LT(with.counters.rayBoxTests, without.counters.rayBoxTests);
    bool planned = false;
    for (const auto& [name, bytes] : with.memory.buffers) planned |= name == "ray finished flags" && bytes == frame.rays.size();
    EXPECT_TRUE(planned) << "the packet buffers are in the memory plan";
}

TEST(Packets, NeedAnImageAndASharedStart) {
    const Scene s = test::shapesScene();
    Frame frame(test::shapesScene(), defaultCamera(s, 32, 24), 32, 24);
    EXPECT_GT(packetTiles(frame.geometry), 0u);
    frame.geometry.imageWidth = 0;  // rays that are not an image's pixels
    EXPECT_EQ(packetTiles(frame.geometry), 0u);
    EXPECT_EQ(frame.trace(Backend::CpuSeq).counters.packetBoxTests, 0u);
}

TEST(ParallelScheme, CountersAndPlanAreConsistent) {
    const Scene s = test::shapesScene();
    const Frame frame(test::shapesScene(), defaultCamera(s, 64, 48), 64, 48);
    const TraceResult r = frame.trace(Backend::Cpu, 4, 2);
    std::uint64_t afterRounds = r.counters.finishedStep1;
    for (std::uint64_t n : r.counters.finishedPerRound) afterRounds += n;
    EXPECT_LE(afterRounds + r.counters.raysCulled, frame.rays.size());
    EXPECT_LE(hitCount(r.hits), frame.rays.size() - r.counters.raysCulled);
    EXPECT_GT(r.counters.finishedStep1, 0u);
    EXPECT_GT(r.counters.rayTriangleTests, 0u);
    EXPECT_EQ(r.memory.total(), [&] {
        std::uint64_t t = 0;
        for (const auto& b : r.memory.buffers) t += b.second;
        return t;
    }());
}

TEST(BackendsAgree, NearlyCoincidentWallsAcrossASplitPlane) {
    // Two walls one float step either side of x = 1, the root split of a scene spanning
    // x in [0, 2], seen obliquely: the watertight test's rounding of t is larger than the
    // gap, so the far wall sometimes wins by t. A cell must then still test the far wall,
    // which is what the filter margin guarantees (docs/correctness.md).
    const float below = std::nextafter(1.0f, 0.0f), above = std::nextafter(1.0f, 2.0f);
    std::vector<Mesh> meshes = {doubleSided(grid({below, -4, -4}, {0, 8, 0}, {0, 0, 8}, 9, 7)),
                                doubleSided(grid({above, -4, -4}, {0, 8, 0}, {0, 0, 8}, 7, 9)),
                                grid({0, -4, -4}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1),   // pins the bounds at x = 0
                                grid({2, 3.9f, 3.9f}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1)};  // and x = 2
    const Scene s = sceneFromMeshes(meshes);
    ASSERT_EQ(sceneBounds(s.triangles).center().x, 1.0f);
    CameraOptions o;
    o.eye = glm::dvec3(0.3, 0.1, 0.2);
    o.target = glm::dvec3(1.0, 1.5, -2.0);
    o.fovDegrees = 100.0;
    const Frame frame(sceneFromMeshes(meshes), defaultCamera(s, 160, 120, o), 160, 120);
    expectAllBackendsAgree(frame, {1, 2, 4}, DivisionAxis::X);
}

TEST(BackendsAgree, StanfordModelsAt640x480) {
    // The acceptance check: cpu with 1, 2, 4, 8 and 16 regions bit-identical to
    // cpu-seq at full size (brute force at this size would take minutes; the small test
    // above ties both to it).
    for (const char* name : {"bunny.glb", "dragon.glb"}) {
        DACRT_REQUIRE_SHARED_SCENE(path, name);
        Scene s = loadGltf(path);
        const Camera cam = defaultCamera(s, 640, 480);
        const Frame frame(std::move(s), cam, 640, 480);
        const TraceResult reference = frame.trace(Backend::CpuSeq);
        ASSERT_GT(hitCount(reference.hits), 10000u);
        for (unsigned regions : {1u, 2u, 4u, 8u, 16u})
            EXPECT_TRUE(identicalHits(reference.hits, frame.trace(Backend::Cpu, regions, 2).hits))
                << name << ", " << regions << " regions";
    }
}

TEST(BackendsAgree, OrthographicCameras) {
    // Rays of many origins sharing one direction: each split's near child is the one the
    // direction's sign points away from, for every ray (FrameGeometry::nearSide).
    // The last two start inside the scene box, obliquely: their origins lie on both sides of
    // splits that the rays cross, so no one origin gives every ray its near child.
    for (const glm::dvec3 eye : {glm::dvec3(0.0, 0.0, 6.0), glm::dvec3(4.0, 3.0, 5.0), glm::dvec3(0.6, 0.35, 0.45),
                                 glm::dvec3(-0.5, 0.3, -0.4)}) {
        SCOPED_TRACE("eye " + std::to_string(eye.x) + " " + std::to_string(eye.y) + " " + std::to_string(eye.z));
        const Frame frame(test::shapesScene(), orthographicView(eye, 1.8), 64, 48);
        ASSERT_FALSE(frame.geometry.raysShareStart);
        ASSERT_EQ(frame.geometry.order, ChildOrder::NearSide);
        expectAllBackendsAgree(frame, {1, 2, 4, 8});
    }
}

TEST(BackendsAgree, RaysWithoutANearSideGoFrontToBackRayByRay) {
    // Two rays from different points travelling opposite ways along x through the same shapes:
    // no one near side, so every split classifies them by direction (ChildOrder::PerRay).
    const Scene s = test::shapesScene();
    const std::vector<Bounds> bounds = allTriangleBounds(s.triangles);
    std::vector<Ray> rays;
    for (int i = 0; i < 64; ++i) {
        const float y = -0.9f + 0.03f * float(i);
        rays.push_back(makeRay({-5, y, 0.1f}, {1, 0.01 * i, 0}));
        rays.push_back(makeRay({5, y, 0}, {-1, 0, 0.01 * i}));
    }
    const FrameGeometry g = frameGeometry(s.triangles, bounds, rays, sceneBounds(s.triangles));
    EXPECT_EQ(g.order, ChildOrder::PerRay);
    const TraceResult reference = traceFrame(g, Backend::Brute);
    EXPECT_GT(hitCount(reference.hits), 20u);
    EXPECT_TRUE(identicalHits(reference.hits, traceFrame(g, Backend::CpuSeq).hits));
    for (unsigned regions : {1u, 2u, 5u})
        EXPECT_TRUE(identicalHits(reference.hits, traceFrame(g, Backend::Cpu, regions, 2).hits)) << regions;
}

// The bands tile the image in whole rows of 8x8 tiles, ascending, as many as a multiple of the
// workers allows, and only for a closest-hit image with more than one worker.
TEST(ImageBands, CoverTheImageInWholeRowsOfTilesForEveryWorker) {
    const Scene s = test::shapesScene();
    for (const int height : {8, 48, 50, 300, 2000}) {
        SCOPED_TRACE("height " + std::to_string(height));
        const Frame frame(test::shapesScene(), defaultCamera(s, 64, height), 64, height);
        for (const unsigned workers : {2u, 3u, 8u}) {
            const std::vector<std::uint32_t> bands = imageBands(frame.geometry, workers);
            const std::uint32_t tileRows = std::uint32_t(height + 7) / 8;
            if (tileRows < 2) {
                EXPECT_TRUE(bands.empty());
                continue;
            }
            ASSERT_GE(bands.size(), 3u);
            EXPECT_EQ(bands.front(), 0u);
            EXPECT_EQ(bands.back(), frame.rays.size());
            for (std::size_t b = 0; b + 1 < bands.size(); ++b) {
                EXPECT_LT(bands[b], bands[b + 1]);
                EXPECT_EQ(bands[b] % (64 * 8), 0u) << "band " << b << " starts inside a row of tiles";
            }
            if (tileRows % workers == 0) EXPECT_EQ((bands.size() - 1) % workers, 0u);
        }
        EXPECT_TRUE(imageBands(frame.geometry, 1).empty()) << "one worker traces the frame as one";
        FrameGeometry anyHit = frame.geometry;
        anyHit.query = HitQuery::Any;
        EXPECT_TRUE(imageBands(anyHit, 2).empty()) << "only closest-hit frames of an image";
        FrameGeometry noImage = frame.geometry;
        noImage.imageWidth = 0;
        EXPECT_TRUE(imageBands(noImage, 2).empty());
    }
}

// Bands of any size, perspective and orthographic, from outside and inside the scene, with and
// without packets, give brute force's hits bit for bit; on three threads, so that a band may
// go to any of them and two bands leave one idle.
TEST(ImageBands, GiveBruteForcesHitsBitForBit) {
    const Scene s = test::shapesScene();
    ThreadPool pool(3);
    std::vector<Camera> cameras{defaultCamera(s, 64, 50), orthographicView(glm::dvec3(4.0, 3.0, 5.0), 1.8),
                                orthographicView(glm::dvec3(0.6, 0.35, 0.45), 1.8)};
    for (std::size_t c = 0; c < cameras.size(); ++c) {
        SCOPED_TRACE("camera " + std::to_string(c));
        const Frame frame(test::shapesScene(), cameras[c], 64, 50);
        const TraceResult reference = frame.trace(Backend::Brute, 0, 2);
        ASSERT_GT(hitCount(reference.hits), frame.rays.size() / 20);
        for (const std::vector<std::uint32_t>& bands : std::vector<std::vector<std::uint32_t>>{
                 {0, 64 * 8, std::uint32_t(frame.rays.size())},
                 {0, 64 * 16, 64 * 24, 64 * 48, std::uint32_t(frame.rays.size())},
                 {0, 64 * 8, 64 * 16, 64 * 24, 64 * 32, 64 * 40, 64 * 48, std::uint32_t(frame.rays.size())}})
            for (const bool packets : {true, false}) {
                DacrtOptions options;
                options.packets = packets;
                const TraceResult r = traceImageBands(frame.geometry, options, pool, bands);
                EXPECT_TRUE(identicalHits(reference.hits, r.hits))
                    << bands.size() - 1 << " bands, packets " << packets;
                EXPECT_EQ(r.regions, 1u);
                EXPECT_EQ(r.threads, std::min<std::size_t>(3, bands.size() - 1));
                EXPECT_GT(r.counters.rayTriangleTests, 0u);
            }
    }
}

// The cpu backend takes the bands for a primary frame large enough to divide, unless regions
// are asked for, and says so in its plan.
TEST(ImageBands, AreTheCpuBackendsWayForAPrimaryFrameUnlessRegionsAreAsked) {
    const Scene s = test::shapesScene();
    const Frame frame(test::shapesScene(), defaultCamera(s, 320, 240), 320, 240);
    const TraceResult reference = frame.trace(Backend::CpuSeq);
    const TraceResult banded = frame.trace(Backend::Cpu, 0, 2);
    EXPECT_TRUE(identicalHits(reference.hits, banded.hits));
    EXPECT_EQ(banded.regions, 1u);
    EXPECT_TRUE(std::any_of(banded.memory.work.begin(), banded.memory.work.end(),
                            [](const WorkLine& w) { return w.name == "image bands side by side" && w.count >= 2; }));
    const TraceResult divided = frame.trace(Backend::Cpu, 2, 2);
    EXPECT_TRUE(identicalHits(reference.hits, divided.hits));
    EXPECT_EQ(divided.regions, 2u);
    EXPECT_TRUE(std::none_of(divided.memory.work.begin(), divided.memory.work.end(),
                             [](const WorkLine& w) { return w.name == "image bands side by side"; }));
}

// The triangle filters read the bounds from columns where the frame has them
// (FrameGeometry::boundsColumns): the same hits, bit for bit, on cpu-seq, the bands and the
// parallel scheme (closest hits, against brute force), and for an occlusion pass's any hits,
// the same hits as from the records on every path (test_subtrees.cpp covers the subtrees').
TEST(Tracers, BoundsColumnsGiveTheRecordsHitsBitForBit) {
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    Frame frame(shapesScene(), 160, 120, o);  // rays enough for the bands (kSequentialBelowRays)
    ThreadPool pool(2);
    std::vector<Bounds> bounds;
    std::vector<float> columns;
    Box box;
    triangleBoundsInParallel(frame.scene.triangles, pool, bounds, box, &columns);
    FrameGeometry withColumns = frame.geometry;
    withColumns.boundsColumns = &columns;
    const TraceResult reference = frame.trace(Backend::Brute, 0, 2);
    for (const auto& [backend, regions] : {std::pair{Backend::CpuSeq, 0u}, {Backend::Cpu, 0u}, {Backend::Cpu, 3u}}) {
        SCOPED_TRACE(toString(backend) + ", " + std::to_string(regions) + " regions");
        const TraceResult traced = traceFrame(withColumns, backend, regions, 2);
        EXPECT_TRUE(identicalHits(reference.hits, traced.hits));
        const bool bands = std::any_of(traced.memory.work.begin(), traced.memory.work.end(),
                                       [](const WorkLine& w) { return w.name == "image bands side by side"; });
        EXPECT_EQ(bands, backend == Backend::Cpu && regions == 0);
    }
    const PassFrame pass(frame, reference.hits, occlusionPass(4, 0.8f));
    FrameGeometry passColumns = pass.geometry;
    passColumns.boundsColumns = &columns;
    for (const auto& [backend, regions] : {std::pair{Backend::CpuSeq, 0u}, {Backend::Cpu, 0u}, {Backend::Cpu, 3u}}) {
        SCOPED_TRACE("occlusion, " + toString(backend) + ", " + std::to_string(regions) + " regions");
        EXPECT_TRUE(identicalHits(pass.trace(backend, regions, 2).hits, traceFrame(passColumns, backend, regions, 2).hits));
    }
}
