// The public API's gpu backend: the same hits as cpu-seq, bit for bit, for closest and any
// hit and for a camera's rays, and after the scene's vertices moved (the triangles kept on the
// device are not reused); the ray queries' structure kept across traces. No validation error.
// Skipped without a Vulkan device (the ray queries without one that has them: tools/mesa25.sh).
#include <exception>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "support/api_support.hpp"

namespace dacrt {
namespace {

using test::onBackend;
using test::phaseNames;
using test::sameHits;

// The gpu tracer under the validation layers, or the reason there is none.
std::optional<Tracer> gpuTracer(std::string& why) {
    TracerOptions o = onBackend(Backend::Gpu, 2);
    o.validate = true;
    try {
        return Tracer(o);
    } catch (const std::exception& e) {  // InputError, or the Vulkan loader's failure
        why = e.what();
        return std::nullopt;
    }
}

TEST(ApiGpu, SameHitsAsCpuSeq) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    const test::SceneArrays s = test::randomSceneArrays(21, 2000);
    const test::RayArrays r = test::randomRayArrays(22, 10000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    EXPECT_TRUE(sameHits(gpu->trace(scene, rays).hits, cpuSeq.trace(scene, rays).hits));
    const std::vector<RayHit> any = gpu->occluded(scene, rays).hits;
    const std::vector<RayHit> closest = cpuSeq.trace(scene, rays).hits;
    ASSERT_EQ(any.size(), closest.size());
    for (std::size_t i = 0; i < any.size(); ++i) ASSERT_EQ(any[i].hit(), closest[i].hit()) << i;

    const RayBatch camera = RayBatch::fromCamera(scene, {}, 96, 64);
    const TraceOutput image = gpu->trace(scene, camera);
    EXPECT_TRUE(sameHits(image.hits, cpuSeq.trace(scene, camera).hits));
    EXPECT_FALSE(image.counters.device.empty());
    EXPECT_GT(image.timings.dispatchMs, 0.0);
    EXPECT_FALSE(gpu->plan(scene, camera).memory.empty());
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

TEST(ApiGpu, ReportsItsDeviceAndTheGpuDefaultsThere) {
    const Tracer cpu(onBackend(Backend::Cpu, 2));
    EXPECT_FALSE(cpu.deviceProperties());
    EXPECT_FALSE(cpu.gpuDefaults());
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    const std::optional<VulkanDeviceProperties> device = gpu->deviceProperties();
    ASSERT_TRUE(device);
    EXPECT_EQ(gpu->device(), device->name + " (" + device->driver + ")");
    const std::optional<Tracer::GpuDefaults> defaults = gpu->gpuDefaults();
    ASSERT_TRUE(defaults);
    // What a trace with the options left open uses.
    const test::SceneArrays s = test::randomSceneArrays(61, 500);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const TraceOutput out = gpu->trace(scene, RayBatch::fromCamera(scene, {}, 64, 48));
    EXPECT_EQ(out.counters.regions, defaults->regions);
    ASSERT_TRUE(out.gpu);
    EXPECT_EQ(out.gpu->rayGroups, defaults->rayGroups);
    // The discrete profile on any device: its shape, in gpuDefaults and in the trace, whose
    // report gives Step 1's work items and their spread.
    TracerOptions discrete = gpu->options();
    discrete.gpu.profile = GpuProfile::Discrete;
    gpu->setOptions(discrete);
    const std::optional<Tracer::GpuDefaults> shaped = gpu->gpuDefaults();
    ASSERT_TRUE(shaped);
    EXPECT_GE(shaped->regions * shaped->rayGroups, 2048u);
    const TraceOutput wide = gpu->trace(scene, RayBatch::fromCamera(scene, {}, 64, 48));
    EXPECT_EQ(wide.counters.regions, shaped->regions);
    ASSERT_TRUE(wide.gpu);
    ASSERT_FALSE(wide.gpu->workPasses.empty());
    EXPECT_EQ(wide.gpu->workPasses.front().workItems, shaped->regions * shaped->rayGroups);
    EXPECT_GE(wide.gpu->parallelism(), 1.0);
    for (std::size_t i = 0; i < out.hits.size(); ++i) {
        EXPECT_EQ(wide.hits[i].primitive, out.hits[i].primitive) << "ray " << i;
        EXPECT_EQ(wide.hits[i].t, out.hits[i].t) << "ray " << i;
    }
}

TEST(ApiGpu, MovedVerticesAreUploadedAgain) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    const test::SceneArrays s = test::randomSceneArrays(41, 2000);
    const test::RayArrays r = test::randomRayArrays(42, 8000);
    TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions);
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    const std::vector<RayHit> before = cpuSeq.trace(scene, rays).hits;
    EXPECT_TRUE(sameHits(gpu->trace(scene, rays).hits, before));
    EXPECT_TRUE(sameHits(gpu->trace(scene, rays).hits, before));  // the triangles kept on the device
    scene.setPositions(test::movedPositions(s.positions, 43, 0.05f));
    const std::vector<RayHit> moved = cpuSeq.trace(scene, rays).hits;
    EXPECT_FALSE(sameHits(moved, before));
    EXPECT_TRUE(sameHits(gpu->trace(scene, rays).hits, moved));
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

std::uint64_t reusedBytes(const FramePlan& plan) {
    for (const FramePlan::Work& w : plan.work)
        if (w.name == "device buffers reused from an earlier frame (bytes)") return w.count;
    ADD_FAILURE() << "the plan has no line for reused device buffers";
    return 0;
}

// Frames of growing, shrinking and equal ray counts, on two scenes, lease their buffers from
// what earlier frames left: stale contents of a reused buffer (a larger frame's rays, ids,
// states) must not reach a later frame's hits.
TEST(ApiGpu, BuffersKeptBetweenFramesOfEverySizeGiveCpuSeqHits) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    const test::SceneArrays small = test::randomSceneArrays(71, 600), large = test::randomSceneArrays(72, 3000);
    const TraceScene scenes[] = {TraceScene::fromArrays(small.positions, small.indices, small.singleSided),
                                 TraceScene::fromArrays(large.positions, large.indices, large.singleSided)};
    const struct {
        int scene;
        std::uint32_t rays;
        bool reuses;  // every buffer of the frame fits one an earlier frame left
    } frames[] = {{0, 9000, false}, {0, 9000, true}, {0, 5000, true}, {1, 2000, false}, {1, 9000, false},
                  {0, 9000, false}, {1, 7000, true}};
    for (std::size_t f = 0; f < std::size(frames); ++f) {
        const TraceScene& scene = scenes[frames[f].scene];
        const test::RayArrays r = test::randomRayArrays(80 + std::uint32_t(f), frames[f].rays);
        const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
        const TraceOutput out = gpu->trace(scene, rays);
        EXPECT_TRUE(sameHits(out.hits, cpuSeq.trace(scene, rays).hits)) << "frame " << f;
        if (frames[f].reuses) EXPECT_GT(reusedBytes(out.plan), 0u) << "frame " << f;
        if (f == 0) EXPECT_EQ(reusedBytes(out.plan), 0u);
        const std::vector<RayHit> any = gpu->occluded(scene, rays).hits;
        for (std::size_t i = 0; i < any.size(); ++i) ASSERT_EQ(any[i].hit(), out.hits[i].hit()) << "frame " << f << " ray " << i;
    }
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

TEST(ApiGpu, RayQueriesKeepTheirStructureAndFollowTheMove) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    if (!gpu->deviceProperties()->rayQuery) GTEST_SKIP() << "the device has no ray query (tools/mesa25.sh has)";
    const test::SceneArrays s = test::randomSceneArrays(51, 1500);
    const test::RayArrays r = test::randomRayArrays(52, 6000);
    const std::vector<float> moved = test::movedPositions(s.positions, 53, 0.05f);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions);
    for (RayQueryBuild build : {RayQueryBuild::Dynamic, RayQueryBuild::Refit, RayQueryBuild::Static}) {
        SCOPED_TRACE(int(build));
        TracerOptions o = onBackend(Backend::RayQuery);
        o.validate = true;
        o.rayQueryBuild = build;
        gpu->setOptions(o);
        TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
        const TraceOutput first = gpu->trace(scene, rays);
        EXPECT_EQ(phaseNames(first)[0], "allocate");
        const TraceOutput again = gpu->trace(scene, rays);
        EXPECT_NE(phaseNames(again)[0], "allocate");  // kept
        EXPECT_TRUE(sameHits(again.hits, first.hits));
        scene.setPositions(moved);
        const TraceOutput followed = gpu->trace(scene, rays);
        const TraceScene fresh = TraceScene::fromArrays(moved, s.indices, s.singleSided);
        EXPECT_TRUE(sameHits(followed.hits, gpu->trace(fresh, rays).hits));
        EXPECT_FALSE(sameHits(followed.hits, first.hits));
    }
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

}  // namespace
}  // namespace dacrt
