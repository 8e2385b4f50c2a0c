// The public API (include/dacrt/) against the library's own path: scenes from files and from
// arrays, the inputs it refuses, every CPU backend and Embree, any-hit queries, camera rays,
// the plan.
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "core/camera.hpp"
#include "core/gltf_loader.hpp"
#include "cpu/predicates.hpp"
#include "library/backend_dispatcher.hpp"
#include "peers/embree_memory.hpp"
#include "support/api_support.hpp"
#include "support/embree_t.hpp"
#include "support/fixtures.hpp"

namespace dacrt {
namespace {

using test::expectInputError;
using test::hitCount;
using test::kRoomScene;
using test::onBackend;
using test::sameHits;

// The meshes as one set of arrays, in the order the loader flattens them (one node per mesh).
test::SceneArrays arraysOf(const std::vector<Mesh>& meshes) {
    test::SceneArrays a;
    for (const Mesh& m : meshes) {
        const std::uint32_t first = std::uint32_t(a.positions.size() / 3);
        for (const glm::vec3& p : m.positions) a.positions.insert(a.positions.end(), {p.x, p.y, p.z});
        for (std::uint32_t i : m.indices) a.indices.push_back(first + i);
        a.singleSided.insert(a.singleSided.end(), m.indices.size() / 3, m.doubleSided ? 0 : 1);
    }
    return a;
}

TEST(ApiScene, ArraysGiveTheLoadedFilesHits) {
    const std::vector<Mesh> meshes = test::shapesMeshes();
    const std::string path = (std::filesystem::temp_directory_path() / "dacrt_api_shapes.glb").string();
    writeGltf(path, meshes, std::nullopt);
    const TraceScene loaded = TraceScene::load(path);
    std::filesystem::remove(path);
    const test::SceneArrays a = arraysOf(meshes);
    const TraceScene arrays = TraceScene::fromArrays(a.positions, a.indices, a.singleSided);

    ASSERT_EQ(arrays.triangleCount(), loaded.triangleCount());
    EXPECT_EQ(arrays.bounds().lo, loaded.bounds().lo);
    EXPECT_EQ(arrays.bounds().hi, loaded.bounds().hi);
    const CameraSpec camera{.eye = std::array{0.5, 1.5, 4.0}, .target = std::array{0.0, -0.3, 0.0}};
    Tracer tracer(onBackend(Backend::CpuSeq));
    const TraceOutput fromFile = tracer.trace(loaded, RayBatch::fromCamera(loaded, camera, 64, 48));
    const TraceOutput fromArrays = tracer.trace(arrays, RayBatch::fromCamera(arrays, camera, 64, 48));
    EXPECT_GT(hitCount(fromFile.hits), fromFile.hits.size() / 2);
    EXPECT_TRUE(sameHits(fromArrays.hits, fromFile.hits));
}

TEST(ApiScene, RefusesBadArraysNamingTheElement) {
    const std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::vector<std::uint32_t> i = {0, 1, 2};
    expectInputError([&] { TraceScene::fromArrays(std::vector<float>(7, 0.0f), i); }, "positions: 7 floats");
    expectInputError([&] { TraceScene::fromArrays(p, std::vector<std::uint32_t>{0, 1, 2, 0}); }, "indices: 4 indices");
    expectInputError([&] { TraceScene::fromArrays(p, std::vector<std::uint32_t>{0, 1, 3}); },
                     "indices[2] (triangle 0) is 3, but positions hold 3 vertices");
    std::vector<float> nan = p;
    nan[4] = std::numeric_limits<float>::quiet_NaN();
    expectInputError([&] { TraceScene::fromArrays(nan, i); }, "positions[4] (vertex 1, y) is nan: coordinates must be finite");
    std::vector<float> far = p;
    far[6] = 2e9f;
    expectInputError([&] { TraceScene::fromArrays(far, i); }, "positions[6] (vertex 2, x) is 2e+09: coordinates must lie within +-1e+09");
    expectInputError([&] { TraceScene::fromArrays(p, std::vector<std::uint32_t>{}); }, "the scene has no triangles");
    expectInputError([&] { TraceScene::fromArrays(p, std::vector<std::uint32_t>{0, 1, 1}); },
                     "no triangles that can be hit (all 1 have no area and were dropped)");
    expectInputError([&] { TraceScene::fromArrays(p, i, std::vector<std::uint8_t>{1, 0}); }, "singleSided: 2 flags for 1 triangles");
    expectInputError([&] { TraceScene::load(test::fixture("bad_nan_position.gltf")); }, "vertex 1 has a non-finite position");
    expectInputError([&] { TraceScene::load(test::fixture("no_such_file.gltf")); }, "no_such_file.gltf");
}

TEST(ApiRays, RefusesBadRaysNamingTheRay) {
    const std::vector<float> o = {0, 0, 0, 1, 1, 1}, d = {0, 0, -1, 0, 0, 1};
    expectInputError([&] { RayBatch::fromArrays(o, std::vector<float>{0, 0, -1, 0, 0, 0}); },
                     "ray 1: origin (1, 1, 1) and direction (0, 0, 0) must be finite and the direction non-zero");
    std::vector<float> nan = o;
    nan[0] = std::numeric_limits<float>::quiet_NaN();
    expectInputError([&] { RayBatch::fromArrays(nan, d); }, "ray 0: origin");
    expectInputError([&] { RayBatch::fromArrays(o, std::vector<float>{0, 0, -1}); }, "directions: 3 floats for 2 origins");
    expectInputError([&] { RayBatch::fromArrays(std::vector<float>{0, 0}, std::vector<float>{0, 0}); }, "origins: 2 floats");
    expectInputError([&] { RayBatch::fromArrays(o, d, std::vector<float>{0.0f}); }, "tmin: 1 values for 2 rays");
    expectInputError([&] { RayBatch::fromArrays(o, d, std::vector<float>{0.0f, -1.0f}); }, "tmin[1] is -1");
    expectInputError([&] { RayBatch::fromArrays(o, d, std::vector<float>{0.0f, 2.0f}, std::vector<float>{1.0f, 1.0f}); },
                     "tmax[1] is 1.000000, below the ray's tmin 2.000000");
    const TraceScene scene = TraceScene::fromArrays(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, std::vector<std::uint32_t>{0, 1, 2});
    expectInputError([&] { RayBatch::fromCamera(scene, {}, 0, 10); }, "width and height must lie in 1..16384");
    expectInputError([&] { RayBatch::fromCamera(scene, {.fovDegrees = 200.0}, 8, 8); }, "field of view");
}

// Embree's t within its rounding (support/embree_t.hpp), every other backend's bit for bit.
static void expectT(Backend b, float t, float expected) {
    if (b == Backend::Embree) {
        EXPECT_NEAR(t, expected, test::embreeTTolerance(expected)) << "embree";
    } else {
        EXPECT_EQ(t, expected) << int(b);
    }
}

// AsGiven: t in units of the caller's direction (a segment to a point ends at 1), and a ray
// made canonical already (makeRay's) traced bit for bit as made.
TEST(ApiRays, DirectionsAsGivenMeasureTInTheirUnits) {
    const TraceScene scene = TraceScene::fromArrays(std::vector<float>{-1, -1, -1, 1, -1, -1, 0, 1, -1},
                                                    std::vector<std::uint32_t>{0, 1, 2});
    const std::vector<float> o = {0, 0, 0, 0, 0, 0, 0, 0, 0}, d = {0, 0, -4, 0, 0, -0.5f, 0, 0, -4};
    const std::vector<float> tmin = {0, 0, 0}, tmax = {1, 1, 0.2f};  // the third ends before the triangle
    const RayBatch given = RayBatch::fromArrays(o, d, tmin, tmax, DirectionLength::AsGiven);
    const RayBatch unit = RayBatch::fromArrays(o, d, tmin, tmax);
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Embree}) {
        Tracer tracer(onBackend(b, 2));
        const TraceOutput out = tracer.trace(scene, given);
        expectT(b, out.hits[0].t, 0.25f);
        EXPECT_FALSE(out.hits[1].hit()) << int(b);  // the segment ends at z = -0.5
        EXPECT_FALSE(out.hits[2].hit()) << int(b);
        expectT(b, tracer.trace(scene, unit).hits[0].t, 1.0f);
        EXPECT_TRUE(tracer.occluded(scene, given).hits[0].hit()) << int(b);
    }

    const Ray made = makeRay({0.1f, 0.2f, 0.3f}, glm::dvec3(0.3, -0.7, -1.1));
    const std::vector<float> mo = {made.origin.x, made.origin.y, made.origin.z}, md = {made.dir.x, made.dir.y, made.dir.z};
    const TraceScene big = TraceScene::fromArrays(std::vector<float>{-9, -9, -5, 9, -9, -5, 0, 9, -5},
                                                  std::vector<std::uint32_t>{0, 1, 2});
    const RayHit asMade = Tracer(onBackend(Backend::Brute)).trace(big, RayBatch::fromArrays(mo, md, {}, {}, DirectionLength::AsGiven)).hits[0];
    const shared::TriangleHit expected = shared::intersectWatertight(made, {-9, -9, -5}, {9, -9, -5}, {0, 9, -5}, false);
    ASSERT_TRUE(expected.hit);
    EXPECT_EQ(asMade.t, expected.t);
    EXPECT_EQ(asMade.u, expected.u);

    expectInputError([&] { RayBatch::fromArrays(o, std::vector<float>{0, 0, 1e-30f, 0, 0, 1, 0, 0, 1}, {}, {},
                                                DirectionLength::AsGiven); },
                     "ray 0: origin");
    expectInputError([&] { RayBatch::fromArrays(o, std::vector<float>{0, 0, 1, 0, 0, 1e30f, 0, 0, 1}, {}, {},
                                                DirectionLength::AsGiven); },
                     "2^-64 .. 2^62");
}

TEST(ApiScene, DroppedTrianglesKeepTheCallersNumbering) {
    // Triangle 1 has no area; a ray at triangle 2 must report 2.
    const std::vector<float> p = {0, 0, -1, 1, 0, -1, 0, 1, -1, 0, 0, -2, 1, 1, -2, 2, 2, -2, 5, 0, -3, 6, 0, -3, 5, 1, -3};
    const std::vector<std::uint32_t> i = {0, 1, 2, 3, 4, 5, 6, 7, 8};
    const TraceScene scene = TraceScene::fromArrays(p, i);
    EXPECT_EQ(scene.triangleCount(), 2u);
    EXPECT_EQ(scene.trianglesDropped(), 1u);
    const std::vector<float> o = {0.2f, 0.2f, 0, 5.2f, 0.2f, 0, 9, 9, 0}, d = {0, 0, -1, 0, 0, -1, 0, 0, -1};
    const RayBatch rays = RayBatch::fromArrays(o, d);
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Embree}) {
        Tracer tracer(onBackend(b, 2));
        const TraceOutput out = tracer.trace(scene, rays);
        ASSERT_EQ(out.hits.size(), 3u);
        EXPECT_EQ(out.hits[0].primitive, 0u);
        EXPECT_EQ(out.hits[1].primitive, 2u);
        expectT(b, out.hits[1].t, 3.0f);
        EXPECT_FALSE(out.hits[2].hit());
        EXPECT_EQ(tracer.occluded(scene, rays).hits[1].hit(), true);
    }
}

// A random scene, rays into it and their brute-force hits.
struct RandomFrame {
    TraceScene scene;
    RayBatch rays;
    TraceOutput brute;
};

RandomFrame randomFrame(std::uint64_t seed, std::uint32_t triangles, std::uint32_t rays) {
    const test::SceneArrays s = test::randomSceneArrays(seed, triangles);
    const test::RayArrays r = test::randomRayArrays(seed + 1, rays);
    RandomFrame f{TraceScene::fromArrays(s.positions, s.indices, s.singleSided),
                  RayBatch::fromArrays(r.origins, r.directions), {}};
    f.brute = Tracer(onBackend(Backend::Brute, 2)).trace(f.scene, f.rays);
    return f;
}

TEST(ApiTracer, CpuBackendsGiveIdenticalHitsAndEmbreeAgrees) {
    const RandomFrame frame = randomFrame(7, 2000, 8000);
    const TraceScene& scene = frame.scene;
    const RayBatch& rays = frame.rays;
    const TraceOutput& brute = frame.brute;
    EXPECT_GT(hitCount(brute.hits), rays.size() / 4);
    EXPECT_LT(hitCount(brute.hits), rays.size());
    EXPECT_TRUE(sameHits(Tracer(onBackend(Backend::CpuSeq)).trace(scene, rays).hits, brute.hits));
    EXPECT_TRUE(sameHits(Tracer(onBackend(Backend::Cpu, 2)).trace(scene, rays).hits, brute.hits));
    TracerOptions regions = onBackend(Backend::Cpu, 2);
    regions.trace.regions = 5;
    EXPECT_TRUE(sameHits(Tracer(regions).trace(scene, rays).hits, brute.hits));

    // Embree's test is not watertight: rays through a shared edge may differ, no more.
    const TraceOutput embree = Tracer(onBackend(Backend::Embree, 2)).trace(scene, rays);
    ASSERT_EQ(embree.hits.size(), brute.hits.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (embree.hits[i].primitive != brute.hits[i].primitive) ++differ;
        else if (brute.hits[i].hit()) EXPECT_NEAR(embree.hits[i].t, brute.hits[i].t, 1e-4f * brute.hits[i].t) << i;
    }
    EXPECT_LE(differ, rays.size() / 1000);
}

TEST(ApiTracer, OccludedAgreesWithTheClosestHitInTheSegment) {
    const test::SceneArrays s = test::randomSceneArrays(11, 2000);
    const test::RayArrays r = test::randomRayArrays(12, 8000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch segments = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
    const TraceOutput closest = Tracer(onBackend(Backend::Brute, 2)).trace(scene, segments);
    const std::size_t occluded = hitCount(closest.hits);
    EXPECT_GT(occluded, segments.size() / 10);
    EXPECT_LT(occluded, segments.size() * 9 / 10);
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Embree}) {
        const TraceOutput any = Tracer(onBackend(b, 2)).occluded(scene, segments);
        ASSERT_EQ(any.hits.size(), segments.size());
        std::size_t disagree = 0;
        for (std::size_t i = 0; i < segments.size(); ++i) {
            disagree += any.hits[i].hit() != closest.hits[i].hit();
            if (any.hits[i].hit() && any.hits[i].primitive != kUnnamedPrimitive)
                EXPECT_LE(any.hits[i].t, r.tmax[i]) << i;
        }
        // dacrt's backends exactly; Embree up to rays through shared edges.
        EXPECT_LE(disagree, b == Backend::Embree ? segments.size() / 1000 : 0u) << int(b);
    }
}

TEST(ApiRays, CameraRaysGiveTheCommandLinesHits) {
    // The library's path as dacrt render takes it: load, face rule, bounds, camera, frame.
    Scene internal = loadGltf(kRoomScene);
    applyCullMode(internal, CullMode::Material);
    const std::vector<Bounds> bounds = allTriangleBounds(internal.triangles);
    const Box box = sceneBounds(internal.triangles);
    const Camera camera = makeCameras(internal, box, {}, 80.0 / 60.0).front();
    const std::vector<Ray> rays = primaryRays(camera, 80, 60);
    FrameGeometry g = frameGeometry(internal.triangles, bounds, rays, box, 80);
    g.frustum = viewFrustum(camera, 80, 60);
    BackendDispatcher dispatcher({}, {Backend::Cpu});
    BackendRequest request;
    request.trace.threads = 2;
    const TraceResult expected = dispatcher.trace(g, request);

    const TraceScene scene = TraceScene::load(kRoomScene);
    const TraceOutput out = Tracer(onBackend(Backend::Cpu, 2)).trace(scene, RayBatch::fromCamera(scene, {}, 80, 60));
    ASSERT_EQ(out.hits.size(), expected.hits.size());
    for (std::size_t i = 0; i < out.hits.size(); ++i) {
        ASSERT_EQ(out.hits[i].primitive, expected.hits[i].prim) << i;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.hits[i].t), std::bit_cast<std::uint32_t>(expected.hits[i].t)) << i;
    }
    EXPECT_EQ(hitCount(out.hits), out.hits.size());  // the room is closed
    // The frustum and back-face skips ran, as on the command line.
    EXPECT_EQ(out.plan.work.size(), expected.memory.work.size());
}

TEST(ApiTracer, PlanIsTheTracesWithoutTracing) {
    const test::SceneArrays s = test::randomSceneArrays(3, 1000);
    const test::RayArrays r = test::randomRayArrays(4, 5000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions);
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu}) {
        Tracer tracer(onBackend(b, 2));
        const FramePlan plan = tracer.plan(scene, rays);
        const TraceOutput traced = tracer.trace(scene, rays);
        ASSERT_FALSE(plan.memory.empty()) << int(b);
        ASSERT_EQ(plan.memory.size(), traced.plan.memory.size()) << int(b);
        for (std::size_t k = 0; k < plan.memory.size(); ++k) {
            EXPECT_EQ(plan.memory[k].name, traced.plan.memory[k].name);
            EXPECT_EQ(plan.memory[k].bytes, traced.plan.memory[k].bytes) << plan.memory[k].name;
        }
        EXPECT_EQ(plan.totalBytes(), traced.plan.totalBytes());
        bool raysLine = false;
        for (const FramePlan::Work& w : plan.work) raysLine |= w.name == "rays" && w.count == rays.size();
        EXPECT_TRUE(raysLine) << int(b);
    }
    // Embree's plan bounds the structure it allocates itself from the triangle count.
    Tracer embree(onBackend(Backend::Embree));
    const FramePlan plan = embree.plan(scene, rays);
    ASSERT_EQ(plan.memory.size(), 3u);
    EXPECT_EQ(plan.memory[0].name, "embree structure and index buffer (at most)");
    EXPECT_EQ(plan.memory[0].bytes, embreeStructureBytesBound(scene.triangleCount()));
    EXPECT_EQ(plan.memory[1].bytes, scene.triangleCount() * sizeof(Triangle));
    EXPECT_EQ(plan.memory[2].bytes, rays.size() * sizeof(Hit));
    EXPECT_EQ(embree.trace(scene, rays).plan.totalBytes(), plan.totalBytes());
}

TEST(ApiTracer, ReportsTypedTimingsAndCounters) {
    const test::SceneArrays s = test::randomSceneArrays(5, 2000);
    const test::RayArrays r = test::randomRayArrays(6, 20000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions);
    TracerOptions cpu = onBackend(Backend::Cpu, 2);
    cpu.trace.regions = 4;
    const TraceOutput parallel = Tracer(cpu).trace(scene, rays);
    EXPECT_GT(parallel.timings.totalMs, 0.0);
    EXPECT_GT(parallel.timings.divideMs, 0.0);
    EXPECT_GT(parallel.timings.step1Ms, 0.0);
    EXPECT_LE(parallel.timings.divideMs + parallel.timings.step1Ms + parallel.timings.transferMs, parallel.timings.totalMs);
    EXPECT_GT(parallel.counters.rayTriangleTests, 0u);
    EXPECT_GT(parallel.counters.rayBoxTests, 0u);
    EXPECT_EQ(parallel.counters.threads, 2u);
    EXPECT_EQ(parallel.counters.regions, 4u);
    const TraceOutput embree = Tracer(onBackend(Backend::Embree, 2)).trace(scene, rays);
    EXPECT_GT(embree.timings.buildMs + embree.timings.traceMs, 0.0);
    EXPECT_EQ(embree.timings.divideMs, 0.0);
    EXPECT_EQ(embree.counters.rayTriangleTests, 0u);
}

// One tracer switched between backends and options gives each one's hits; what it cannot
// switch (the device, a Vulkan backend without one) is refused.
TEST(ApiTracer, SetOptionsSwitchesBackendsAndOptions) {
    const RandomFrame frame = randomFrame(5, 500, 2000);
    Tracer tracer(onBackend(Backend::Brute, 2));
    TracerOptions cpu = onBackend(Backend::Cpu, 2);
    cpu.trace.regions = 3;
    tracer.setOptions(cpu);
    EXPECT_EQ(tracer.options().trace.regions, 3u);
    const TraceOutput out = tracer.trace(frame.scene, frame.rays);
    EXPECT_TRUE(sameHits(out.hits, frame.brute.hits));
    EXPECT_EQ(out.counters.regions, 3u);
    TracerOptions embree = onBackend(Backend::Embree);
    embree.trace.regions = 3;
    expectInputError([&] { tracer.setOptions(embree); }, "--regions is not an option of --backend embree");
    EXPECT_EQ(tracer.options().trace.backend, Backend::Cpu);  // a refused choice changes nothing
    expectInputError([&] { tracer.setOptions(onBackend(Backend::Gpu)); }, "gpu runs on a Vulkan device");
    TracerOptions device = cpu;
    device.validate = true;
    expectInputError([&] { tracer.setOptions(device); }, "chosen when a Tracer is made");
    EXPECT_TRUE(tracer.device().empty());
}

TEST(ApiTracer, RefusesOptionsItsBackendDoesNotTake) {
    TracerOptions embree = onBackend(Backend::Embree);
    embree.trace.regions = 3;
    expectInputError([&] { Tracer t(embree); }, "--regions is not an option of --backend embree");
    TracerOptions cpu = onBackend(Backend::Cpu);
    cpu.device = "0";
    expectInputError([&] { Tracer t(cpu); }, "--device");
}

}  // namespace
}  // namespace dacrt
