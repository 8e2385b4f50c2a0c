// Scenes whose vertices move between traces (TraceScene::setPositions, and the library's own
// replaceScene for the commands' posed scenes): every backend follows the moved triangles, dacrt's
// bit for bit as brute force does, Embree's kept structure as a fresh one; what it refuses.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "core/gltf_loader.hpp"
#include "cpu/options.hpp"
#include "library/render_inputs.hpp"
#include "support/api_support.hpp"

namespace dacrt {
namespace {

using test::expectInputError;
using test::onBackend;
using test::phaseNames;
using test::sameHits;

// A random scene, the same scene moved, and rays into both.
struct MovingFrame {
    test::SceneArrays scene = test::randomSceneArrays(31, 1500);
    std::vector<float> moved = test::movedPositions(scene.positions, 32, 0.05f);
    test::RayArrays r = test::randomRayArrays(33, 6000);
    RayBatch rays = RayBatch::fromArrays(r.origins, r.directions);

    TraceScene original() const { return TraceScene::fromArrays(scene.positions, scene.indices, scene.singleSided); }
    TraceScene fresh() const { return TraceScene::fromArrays(moved, scene.indices, scene.singleSided); }
};

TracerOptions embreeWith(EmbreeBuild build) {
    TracerOptions o = onBackend(Backend::Embree, 2);
    o.embree.build = build;
    return o;
}

TEST(ApiMovingScene, DacrtBackendsTraceTheMovedTrianglesAsBruteForceDoes) {
    const MovingFrame f;
    TraceScene scene = f.original();
    const TraceOutput before = Tracer(onBackend(Backend::Brute, 2)).trace(scene, f.rays);
    std::vector<Tracer> tracers;
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu}) {
        tracers.emplace_back(onBackend(b, 2));
        ASSERT_TRUE(sameHits(tracers.back().trace(scene, f.rays).hits, before.hits)) << toString(b);
    }
    scene.setPositions(f.moved);
    const TraceScene fresh = f.fresh();
    const TraceOutput expected = Tracer(onBackend(Backend::Brute, 2)).trace(fresh, f.rays);
    EXPECT_FALSE(sameHits(expected.hits, before.hits));  // the move changed what the rays meet
    EXPECT_EQ(scene.triangleCount(), fresh.triangleCount());
    EXPECT_EQ(scene.bounds().lo, fresh.bounds().lo);
    EXPECT_EQ(scene.bounds().hi, fresh.bounds().hi);
    for (Tracer& t : tracers) {
        EXPECT_TRUE(sameHits(t.trace(scene, f.rays).hits, expected.hits)) << toString(t.options().trace.backend);
        EXPECT_TRUE(sameHits(t.occluded(scene, f.rays).hits, t.occluded(fresh, f.rays).hits));
    }
}

TEST(ApiMovingScene, EmbreeKeepsItsStructureAndFollowsTheMoveAsAFreshScene) {
    const MovingFrame f;
    for (EmbreeBuild build : {EmbreeBuild::Dynamic, EmbreeBuild::Refit, EmbreeBuild::Static}) {
        SCOPED_TRACE(toString(build));
        TraceScene scene = f.original();
        Tracer tracer(embreeWith(build));
        // The first trace builds; a later one is the next frame of a dynamic scene: rebuilt,
        // refitted, or (static) traced as it stands.
        const TraceOutput first = tracer.trace(scene, f.rays);
        EXPECT_EQ(phaseNames(first), (std::vector<std::string>{"build", "trace"}));
        const TraceOutput again = tracer.trace(scene, f.rays);
        EXPECT_TRUE(sameHits(again.hits, first.hits));
        const std::vector<std::string> update = build == EmbreeBuild::Dynamic ? std::vector<std::string>{"build", "trace"}
                                                : build == EmbreeBuild::Refit ? std::vector<std::string>{"refit", "trace"}
                                                                              : std::vector<std::string>{"trace"};
        EXPECT_EQ(phaseNames(again), update);

        scene.setPositions(f.moved);
        const TraceOutput moved = tracer.trace(scene, f.rays);
        // A static structure cannot follow the move: it is built again.
        const std::vector<std::string> rebuilt = {"build", "trace"};
        EXPECT_EQ(phaseNames(moved), build == EmbreeBuild::Static ? rebuilt : update);
        const TraceScene fresh = f.fresh();
        Tracer freshTracer(embreeWith(build));
        EXPECT_TRUE(sameHits(moved.hits, freshTracer.trace(fresh, f.rays).hits));
        EXPECT_TRUE(sameHits(tracer.occluded(scene, f.rays).hits, freshTracer.occluded(fresh, f.rays).hits));
    }
}

TEST(ApiMovingScene, EmbreeKeepsAStructurePerOptionSetAndFreesThemForAnotherScene) {
    const MovingFrame f;
    const TraceScene scene = f.original();
    Tracer tracer(embreeWith(EmbreeBuild::Refit));
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "build");
    tracer.setOptions(embreeWith(EmbreeBuild::Static));
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "build");
    tracer.setOptions(embreeWith(EmbreeBuild::Refit));
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "refit");  // the refit one was kept
    const TraceScene other = f.fresh();
    EXPECT_EQ(phaseNames(tracer.trace(other, f.rays))[0], "build");
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "build");  // freed by the other scene's trace
}

TEST(ApiMovingScene, ReleasedStructuresAreBuiltAgainByTheNextTrace) {
    const MovingFrame f;
    const TraceScene scene = f.original();
    Tracer tracer(embreeWith(EmbreeBuild::Refit));
    const TraceOutput first = tracer.trace(scene, f.rays);
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "refit");
    tracer.releaseKept();
    const TraceOutput rebuilt = tracer.trace(scene, f.rays);
    EXPECT_EQ(phaseNames(rebuilt)[0], "build");  // as the scene's first trace
    EXPECT_TRUE(sameHits(rebuilt.hits, first.hits));
    EXPECT_EQ(phaseNames(tracer.trace(scene, f.rays))[0], "refit");  // kept again
    // On a backend that keeps nothing between traces it frees nothing and changes nothing.
    Tracer cpu(onBackend(Backend::Cpu, 2));
    const TraceOutput before = cpu.trace(scene, f.rays);
    cpu.releaseKept();
    EXPECT_TRUE(sameHits(cpu.trace(scene, f.rays).hits, before.hits));
}

TEST(ApiMovingScene, ATriangleMovedToNoAreaIsNeverHit) {
    // Triangle 0 in front of triangle 1; rays along -z through both.
    const std::vector<float> p = {-1, -1, -1, 1, -1, -1, 0, 1, -1, -2, -2, -2, 2, -2, -2, 0, 2, -2};
    const std::vector<std::uint32_t> i = {0, 1, 2, 3, 4, 5};
    const std::vector<float> o = {0.0f, 0.0f, 0.0f, 0.5f, -1.0f, 0.0f, 0.25f, 0.0f, 0.0f}, d = {0, 0, -1, 0, 0, -1, 0, 0, -1};
    const RayBatch rays = RayBatch::fromArrays(o, d);
    // Collapsed to a point on the first ray, then to a segment along the second, through the third's origin.
    const std::vector<std::vector<float>> collapsed = {
        {0, 0, -1, 0, 0, -1, 0, 0, -1, -2, -2, -2, 2, -2, -2, 0, 2, -2},
        {0, -1, -1, 0.5f, -1, -1, 1, -1, -1, -2, -2, -2, 2, -2, -2, 0, 2, -2},
        {-1, 0, -1, 0.25f, 0, -1, 1, 0, -1, -2, -2, -2, 2, -2, -2, 0, 2, -2}};
    for (Backend b : {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Embree}) {
        SCOPED_TRACE(toString(b));
        for (const std::vector<float>& positions : collapsed) {
            TraceScene scene = TraceScene::fromArrays(p, i);
            Tracer tracer(onBackend(b, 2));
            EXPECT_EQ(tracer.trace(scene, rays).hits[0].primitive, 0u);
            scene.setPositions(positions);
            EXPECT_EQ(scene.triangleCount(), 2u);  // still traced, never hit
            const TraceOutput out = tracer.trace(scene, rays);
            for (const RayHit& h : out.hits) EXPECT_EQ(h.primitive, 1u);
            for (const RayHit& h : tracer.occluded(scene, rays).hits) EXPECT_TRUE(h.hit());
        }
    }
}

TEST(ApiMovingScene, SetPositionsRefusesWhatFromArraysRefusesAndChangesNothing) {
    // Triangle 1 has no area and was dropped.
    const std::vector<float> p = {0, 0, -1, 1, 0, -1, 0, 1, -1, 0, 0, -2, 1, 1, -2, 2, 2, -2};
    const std::vector<std::uint32_t> i = {0, 1, 2, 3, 4, 5};
    TraceScene scene = TraceScene::fromArrays(p, i);
    const std::vector<float> o = {0.2f, 0.2f, 0.0f}, d = {0, 0, -1};
    const RayBatch rays = RayBatch::fromArrays(o, d);
    Tracer tracer(onBackend(Backend::Cpu, 2));
    const TraceOutput before = tracer.trace(scene, rays);
    expectInputError([&] { scene.setPositions(std::vector<float>(p.begin(), p.end() - 3)); }, "6 vertices");
    std::vector<float> bad = p;
    bad[4] = NAN;
    expectInputError([&] { scene.setPositions(bad); }, "positions[4] (vertex 1, y)");
    bad[4] = 2e9f;
    expectInputError([&] { scene.setPositions(bad); }, "within +-");
    bad = p;
    bad[17] = -3.0f;  // triangle 1 gains area
    expectInputError([&] { scene.setPositions(bad); }, "triangle 1 had no area");
    EXPECT_TRUE(sameHits(tracer.trace(scene, rays).hits, before.hits));
    EXPECT_EQ(scene.trianglesDropped(), 1u);

    TraceScene loaded = TraceScene::load(test::kRoomScene);
    expectInputError([&] { loaded.setPositions(p); }, "load it again at the new instant");
}

TEST(ApiMovingScene, ReplaceSceneWritesThePosedTrianglesWhereTheTracerReadsThem) {
    // The commands' bridge: a posed scene into the TraceScene's own array, which keeps its address.
    Scene posed = loadGltf(test::kRoomScene);
    Scene moved = posed;
    for (Triangle& t : moved.triangles)
        for (glm::vec3* v : {&t.v0, &t.v1, &t.v2}) *v += glm::vec3(0.25f, -0.125f, 0.5f) * (v->y + 1.0f);
    const Box box = sceneBounds(posed.triangles);
    TraceScene scene = adoptScene(std::move(posed), box);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 64, 48);
    Tracer embree(embreeWith(EmbreeBuild::Refit));
    Tracer cpu(onBackend(Backend::Cpu, 2));
    embree.trace(scene, rays);
    const Triangle* where = sceneOf(scene).triangles.data();
    const std::uint64_t version = sceneOf(scene).trianglesVersion;
    replaceScene(scene, moved);
    EXPECT_EQ(sceneOf(scene).triangles.data(), where);
    EXPECT_NE(sceneOf(scene).trianglesVersion, version);
    const Box expectedBox = sceneBounds(moved.triangles);
    EXPECT_EQ(boxOf(scene).lo, expectedBox.lo);
    EXPECT_EQ(boxOf(scene).hi, expectedBox.hi);
    const TraceScene fresh = adoptScene(moved, expectedBox);
    const TraceOutput refitted = embree.trace(scene, rays);
    EXPECT_EQ(phaseNames(refitted)[0], "refit");
    EXPECT_TRUE(sameHits(refitted.hits, Tracer(embreeWith(EmbreeBuild::Refit)).trace(fresh, rays).hits));
    EXPECT_TRUE(sameHits(cpu.trace(scene, rays).hits, Tracer(onBackend(Backend::Brute, 2)).trace(fresh, rays).hits));

    moved.triangles.pop_back();
    EXPECT_THROW(replaceScene(scene, moved), InternalError);
}

}  // namespace
}  // namespace dacrt
