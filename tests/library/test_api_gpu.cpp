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

// The count of a plan's work line, or none.
std::optional<std::uint64_t> workCount(const FramePlan& plan, const std::string& name) {
    for (const FramePlan::Work& w : plan.work)
        if (w.name == name) return w.count;
    return std::nullopt;
}

// Slot by slot: a ray made in the same slots, and the same visibility (any hit: the triangle
// found may differ).
::testing::AssertionResult sameVisibility(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " slots against " << b.size();
    for (std::size_t i = 0; i < a.size(); ++i)
        if ((a[i].primitive == kNotTracedPrimitive) != (b[i].primitive == kNotTracedPrimitive) || a[i].hit() != b[i].hit())
            return ::testing::AssertionFailure() << "slot " << i << ": primitive " << a[i].primitive << " against "
                                                 << b[i].primitive;
    return ::testing::AssertionSuccess();
}

// The room's passes at 32x24: a directional light's shadow, the centre's point light's, one
// occlusion ray per hit (each fewer rays than an eighth of the 11,948 triangles: the pass
// cull's grid pays), and sixteen (more: no grid).
std::vector<FramePass> fewAndManyRays(const TraceScene& scene) {
    FramePass sun{.name = "shadow: sun", .kind = PassKind::Shadow};
    sun.light.kind = LightKind::Directional;
    sun.light.direction = {0.36f, -0.8f, -0.48f};
    const std::vector<FramePass> centre = test::lightAndOcclusion(scene, 1);
    FramePass many = centre[1];
    many.name = "occlusion: many rays";
    many.raysPerHit = 16;
    return {sun, centre[0], centre[1], many};
}

TEST(ApiGpu, FramePassesCullWhatCpuSeqCulls) {
    // The gpu makes the rays of the passes the cull may thin on the host (the device's, bit for
    // bit) and traces the triangles cpu-seq's cull keeps; the pass of many rays is made on the
    // device over every triangle, as cpu-seq traces it. Every slot agrees, and so do the rays
    // made, the cull's work lines and the rays culled.
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    // 108 pixels: a pass of a ray per pixel at most has fewer rays than the grid's rule asks of
    // the room's 11,948 triangles (kTrianglesPerRayForTheGrid), the pass of 16 per pixel more.
    const TraceScene scene = TraceScene::load(test::kRoomScene);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 12, 9);
    const std::vector<FramePass> passes = fewAndManyRays(scene);
    // Each pass on its own, as the gpu traces them (so few rays would go together on cpu-seq).
    TracerOptions apart = onBackend(Backend::CpuSeq);
    apart.trace.dacrt.passTracing = PassTracing::Apart;
    const FrameOutput expected = Tracer(apart).traceFrame(scene, rays, passes);
    const FrameOutput device = gpu->traceFrame(scene, rays, passes);
    ASSERT_EQ(device.passes.size(), passes.size());
    const std::string outside = "skipped: outside the pass's rays' bounds";
    for (std::size_t k = 0; k < passes.size(); ++k) {
        SCOPED_TRACE(passes[k].name);
        const TraceOutput& got = device.passes[k].output;
        const TraceOutput& want = expected.passes[k].output;
        EXPECT_EQ(device.passes[k].rays, expected.passes[k].rays);
        EXPECT_TRUE(sameVisibility(got.hits, want.hits));
        EXPECT_GT(test::hitCount(want.hits), 0u);
        for (const std::string& line : {outside, std::string("skipped: back-facing"), std::string("triangles traced")}) {
            ASSERT_TRUE(workCount(got.plan, line)) << line;
            EXPECT_EQ(workCount(got.plan, line), workCount(want.plan, line)) << line;
        }
        EXPECT_EQ(got.counters.raysCulled, want.counters.raysCulled);
        const bool fewRays = k + 1 < passes.size();
        EXPECT_EQ(*workCount(got.plan, outside) > 0, fewRays) << "the grid pays for few rays only";
    }
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

TEST(ApiGpu, AnOcclusionPassIsOneBatchUnlessTheDeviceMemoryHoldsLess) {
    // With buffer device addresses a pass's rays are not held to one binding: one batch. A
    // memory cap that leaves room for a few samples' slots splits it into batches, which draw
    // the whole pass's samples: the same slots.
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    if (!gpu->deviceProperties()->bufferDeviceAddress) GTEST_SKIP() << "the device lacks buffer device addresses";
    const TraceScene scene = TraceScene::load(test::kRoomScene);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 40, 30);
    const std::vector<FramePass> passes = {fewAndManyRays(scene).back()};
    const FrameOutput whole = gpu->traceFrame(scene, rays, passes);
    ASSERT_EQ(whole.passes.size(), 1u);
    EXPECT_FALSE(workCount(whole.passes[0].output.plan, "occlusion batches"));
    // The primary pass's device buffers stay on the device; half of what the cap leaves holds
    // the slots of 6 samples.
    std::uint64_t primaryBytes = 0;
    for (const FramePlan::Buffer& b : whole.primary.plan.memory) primaryBytes += b.name.starts_with("device: ") ? b.bytes : 0;
    TracerOptions capped = gpu->options();
    capped.gpu.memoryBytes = primaryBytes + 2 * 6 * rays.size() * (64 + 16 + 8);
    gpu->setOptions(capped);
    const FrameOutput batched = gpu->traceFrame(scene, rays, passes);
    ASSERT_EQ(batched.passes.size(), 1u);
    const std::optional<std::uint64_t> batches = workCount(batched.passes[0].output.plan, "occlusion batches");
    ASSERT_TRUE(batches);
    EXPECT_GT(*batches, 1u);
    EXPECT_EQ(batched.passes[0].rays, whole.passes[0].rays);
    EXPECT_TRUE(sameVisibility(batched.passes[0].output.hits, whole.passes[0].output.hits));
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

// The device bytes of a plan (its "device: " lines).
std::uint64_t deviceBytes(const FramePlan& plan) {
    std::uint64_t bytes = 0;
    for (const FramePlan::Buffer& b : plan.memory) bytes += b.name.starts_with("device: ") ? b.bytes : 0;
    return bytes;
}

TEST(ApiGpu, AFrameBeyondTheDeviceMemoryRunsInTriangleBatchesWithCpuSeqHits) {
    // A memory cap below what the frame's device buffers need, but above what its rays need
    // alone: the triangles are traced in batches, and the merged hits are cpu-seq's, bit for
    // bit (closest hits), slot for slot (a lit frame's passes).
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    const test::SceneArrays s = test::randomSceneArrays(41, 12000);
    const test::RayArrays r = test::randomRayArrays(42, 3000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
    const TraceOutput whole = gpu->trace(scene, rays);
    EXPECT_FALSE(workCount(whole.plan, "triangle batches"));
    const TracerOptions uncapped = gpu->options();
    TracerOptions capped = uncapped;
    capped.gpu.memoryBytes = deviceBytes(whole.plan) * 6 / 10;
    gpu->setOptions(capped);
    const TraceOutput batched = gpu->trace(scene, rays);
    const std::optional<std::uint64_t> batches = workCount(batched.plan, "triangle batches");
    ASSERT_TRUE(batches);
    EXPECT_GE(*batches, 2u);
    EXPECT_TRUE(sameHits(batched.hits, whole.hits));
    EXPECT_TRUE(sameHits(batched.hits, cpuSeq.trace(scene, rays).hits));
    EXPECT_TRUE(sameVisibility(gpu->occluded(scene, rays).hits, cpuSeq.occluded(scene, rays).hits));

    // A lit frame of the room: the primary pass in batches; its passes made on the host.
    const TraceScene room = TraceScene::load(test::kRoomScene);
    const RayBatch camera = RayBatch::fromCamera(room, {}, 32, 24);
    const std::vector<FramePass> passes = fewAndManyRays(room);
    gpu->setOptions(uncapped);
    const FrameOutput unbatched = gpu->traceFrame(room, camera, passes);
    capped.gpu.memoryBytes = deviceBytes(unbatched.primary.plan) * 7 / 10;
    gpu->setOptions(capped);
    const FrameOutput lit = gpu->traceFrame(room, camera, passes);
    const FrameOutput expected = cpuSeq.traceFrame(room, camera, passes);
    EXPECT_TRUE(workCount(lit.primary.plan, "triangle batches"));
    EXPECT_TRUE(sameHits(lit.primary.hits, expected.primary.hits));
    ASSERT_EQ(lit.passes.size(), passes.size());
    for (std::size_t k = 0; k < passes.size(); ++k)
        EXPECT_TRUE(sameVisibility(lit.passes[k].output.hits, expected.passes[k].output.hits)) << passes[k].name;

    // Where the rays alone exceed the cap, no batch of triangles fits: refused, the limit named.
    capped.gpu.memoryBytes = 65536;
    gpu->setOptions(capped);
    test::expectInputError([&] { gpu->trace(scene, rays); }, "memory cap (GpuTuning::memoryBytes) of 65536 bytes");
    EXPECT_EQ(gpu->validationErrors(), 0u);
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

// The ticks of one stage of a report, or none.
std::optional<std::uint64_t> stageTicks(const DeviceReport& report, const std::string& stage) {
    for (const DeviceReport::StageTicks& s : report.stageTicks)
        if (s.name == stage) return s.ticks;
    return std::nullopt;
}

TEST(ApiGpu, StageClocksTellTheKernelsStagesApartAndKeepCpuSeqHits) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    if (!gpu->deviceProperties()->subgroupClock) GTEST_SKIP() << "the device has no subgroup clock";
    const test::SceneArrays s = test::randomSceneArrays(71, 3000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch camera = RayBatch::fromCamera(scene, {}, 96, 64);
    const TraceOutput plain = gpu->trace(scene, camera);
    ASSERT_TRUE(plain.gpu);
    EXPECT_TRUE(plain.gpu->stageTicks.empty());

    const TracerOptions unclocked = gpu->options();
    TracerOptions clocked = unclocked;
    clocked.gpu.stageClocks = true;
    gpu->setOptions(clocked);
    const TraceOutput timed = gpu->trace(scene, camera);
    EXPECT_TRUE(sameHits(timed.hits, plain.hits));
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    EXPECT_TRUE(sameHits(timed.hits, cpuSeq.trace(scene, camera).hits));
    ASSERT_TRUE(timed.gpu);
    ASSERT_EQ(timed.gpu->stageTicks.size(), 6u);
    const std::uint64_t launches = stageTicks(*timed.gpu, "launches").value_or(0);
    std::uint64_t stages = 0;
    for (const char* stage : {"ray partitions", "triangle partitions", "leaf tests"}) {
        const std::optional<std::uint64_t> ticks = stageTicks(*timed.gpu, stage);
        ASSERT_TRUE(ticks) << stage;
        EXPECT_GT(*ticks, 0u) << stage;  // every frame with a hit filters and tests
        stages += *ticks;
    }
    stages += stageTicks(*timed.gpu, "stack and slices").value_or(0) + stageTicks(*timed.gpu, "waiting").value_or(0);
    // A launch brackets its stages, which never overlap.
    EXPECT_GE(launches, stages);
    // Any-hit traces run the clocked kernel too.
    const TraceOutput any = gpu->occluded(scene, camera);
    ASSERT_TRUE(any.gpu);
    EXPECT_GT(stageTicks(*any.gpu, "leaf tests").value_or(0), 0u);

    // Frames whose arrays are reached by address run a kernel without clocks: refused.
    if (gpu->deviceProperties()->bufferDeviceAddress) {
        clocked.gpu.bufferBytes = 65536;
        gpu->setOptions(clocked);
        test::expectInputError([&] { gpu->trace(scene, camera); }, "--stage-clocks times the kernel that binds every array");
    }
    EXPECT_EQ(gpu->validationErrors(), 0u);
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
    // Released (Tracer::releaseKept), the next frame finds nothing kept and the same hits.
    const test::RayArrays r = test::randomRayArrays(99, 9000);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
    const TraceOutput before = gpu->trace(scenes[0], rays);
    EXPECT_GT(reusedBytes(gpu->trace(scenes[0], rays).plan), 0u);
    gpu->releaseKept();
    const TraceOutput after = gpu->trace(scenes[0], rays);
    EXPECT_EQ(reusedBytes(after.plan), 0u);
    EXPECT_TRUE(sameHits(after.hits, before.hits));
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
