// Whole images: the gpu backend against cpu-seq, bit for bit, under the validation layers.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "support/gpu_support.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/gpu_tracer.hpp"
#include "core/procedural.hpp"
#include "support/frames.hpp"
#include "support/tight_box_scene.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

const WorkLine* workLine(const MemoryPlan& plan, const std::string& name) {
    for (const WorkLine& w : plan.work)
        if (w.name == name) return &w;
    return nullptr;
}

Scene shapes() {
    return sceneFromMeshes({icosphere({-0.8f, 0.0f, 0.0f}, 0.7f, 3), torus({0.9f, -0.2f, 0.3f}, 0.6f, 0.2f, 40, 16),
                            box({-0.3f, -1.0f, -1.2f}, {0.4f, 0.6f, -0.6f}), grid({-2, -1, 2}, {4, 0, 0}, {0, 0, -4}, 12, 12)},
                           "shapes");
}

// The work item report against the counters: every work item in one of the dispatches, each
// dispatch's mean within its largest cost, the longest chain within the whole work and at least
// Step 1's costliest item.
void expectConsistentWorkReport(const TraceResult& r) {
    const GpuReport& g = *r.gpu;
    ASSERT_FALSE(g.workPasses.empty());
    EXPECT_EQ(g.workPasses.front().name, "step1");
    EXPECT_EQ(g.workPasses.front().items, r.regions * g.rayGroups);
    std::uint64_t items = 0;
    double cost = 0.0;
    for (const GpuWorkPass& p : g.workPasses) {
        items += p.items;
        cost += p.meanCost * p.items;
        EXPECT_LE(p.meanCost, double(p.maxCost)) << p.name;
    }
    EXPECT_EQ(items, std::uint64_t(g.workItemsRun) + g.workItemsEmpty);
    EXPECT_NEAR(cost, double(g.workCost), 1e-6 * double(g.workCost));
    EXPECT_GT(g.workCost, 0u);
    EXPECT_GE(g.longestChainCost, g.workPasses.front().maxCost);
    EXPECT_LE(g.longestChainCost, g.workCost);
}

// gpu == cpu-seq, bit for bit, for every region count (0: the tuning's profile's default; work
// items too large for llvmpipe's loop limiter run in several slices; none may be cut short).
// Returns the transfer work items of all the frames traced.
std::uint64_t expectGpuMatchesCpu(gpu::Context& context, const Frame& frame, std::initializer_list<unsigned> regionCounts,
                                  const GpuTuning& tuning = {}, const DacrtOptions& dacrt = {}) {
    const TraceResult reference = frame.trace(Backend::CpuSeq);
    std::uint64_t transferWorkItems = 0;
    for (unsigned regions : regionCounts) {
        TraceOptions o;
        o.backend = Backend::Gpu;
        o.regions = regions;
        o.dacrt = dacrt;
        ThreadPool pool(2);
        const TraceResult r = GpuTracer(context, pool, o, tuning).trace(frame.geometry);
        EXPECT_TRUE(identicalHits(reference.hits, r.hits)) << r.regions << " regions, " << r.gpu->rayGroups << " ray groups";
        EXPECT_EQ(r.gpu->dispatches, r.gpu->dispatchMs.size());
        if (tuning.rayGroups) {
            EXPECT_EQ(r.gpu->rayGroups, tuning.rayGroups);
        }
        std::uint64_t planned = 0;
        for (const GpuWorkPass& p : r.gpu->workPasses) planned += p.items;
        EXPECT_EQ(r.gpu->workItemsRun + r.gpu->workItemsEmpty, planned);
        if (tuning.profile != GpuProfile::Discrete) {  // even groups: rayGroups in every region
            EXPECT_EQ(planned, (r.regions + r.counters.transferWorkItems) * r.gpu->rayGroups);
        }
        EXPECT_GE(r.gpu->slices, r.gpu->workItemsRun);
        expectConsistentWorkReport(r);
        transferWorkItems += r.counters.transferWorkItems;
    }
    EXPECT_TRUE(noValidationErrors(context));
    return transferWorkItems;
}

constexpr GpuTuning kDiscreteProfile{.profile = GpuProfile::Discrete};

TraceOptions gpuOptions(unsigned regions) {
    TraceOptions o;
    o.backend = Backend::Gpu;
    o.regions = regions;
    return o;
}

// A frame seen from inside the scene through a 100-degree camera.
Frame insideView(const std::vector<Mesh>& meshes, glm::dvec3 eye, glm::dvec3 target, int width, int height) {
    CameraOptions o;
    o.eye = eye;
    o.target = target;
    o.fovDegrees = 100.0;
    const Scene s = sceneFromMeshes(meshes);
    return Frame(sceneFromMeshes(meshes), defaultCamera(s, width, height, o), width, height);
}

// The shapes from above and in front: their hits face every way, and so do rays leaving them.
CameraOptions viewFromAboveFront() {
    CameraOptions view;
    view.eye = glm::dvec3(0.5, 1.5, 4.0);
    return view;
}

}  // namespace

TEST(GpuImages, ProceduralShapes) {
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 96, 72), 96, 72);
    expectGpuMatchesCpu(*context, frame, {1, 2, 3, 4, 8, 16});
    expectGpuMatchesCpu(*context, frame, {1, 4}, GpuTuning{.workgroupSize = 32});
}

TEST(GpuImages, RaysFromSurfacesInEveryDirection) {
    // Occlusion and shadow rays made on the host from the primary hits: no common near side
    // (kOrderPerRay: rays classified per split for closest hits), any hit or the closest, with
    // transfer rounds in both directions and ray groups.
    DACRT_REQUIRE_GPU(context);
    const Frame frame(shapes(), 40, 30, viewFromAboveFront());
    const TraceResult primary = frame.trace(Backend::CpuSeq);
    for (const SecondaryPass& p : {occlusionPass(3, 0.8f), occlusionPass(2, kNoHitT), pointShadowPass({0.3f, 1.6f, 0.4f})}) {
        for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
            SCOPED_TRACE(p.name + (query == HitQuery::Any ? ", any hit" : ", closest hit"));
            const PassFrame pass(frame, primary.hits, p, query);
            const TraceResult reference = pass.trace(Backend::CpuSeq);
            for (unsigned regions : {1u, 3u})
                for (std::uint32_t groups : {1u, 2u}) {
                    ThreadPool pool(2);
                    const TraceResult r = GpuTracer(*context, pool, gpuOptions(regions), GpuTuning{0, groups}).trace(pass.geometry);
                    EXPECT_TRUE(query == HitQuery::Closest ? identicalHits(reference.hits, r.hits)
                                                           : identicalVisibility(reference.hits, r.hits))
                        << regions << " regions, " << groups << " ray groups";
                }
        }
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, AnyHitRaysOfDifferentLengthsAreTracedWithTheirOwn) {
    // A pass's rays share their segment, and the kernel then takes tmin and tmax once
    // (DACRT_SPEC_SHARED_SEGMENT); where one ray in three is shorter they do not, and each ray's
    // own segment and best hit are read.
    DACRT_REQUIRE_GPU(context);
    const Frame frame(shapes(), 40, 30, viewFromAboveFront());
    const TraceResult primary = frame.trace(Backend::CpuSeq);
    PassFrame pass(frame, primary.hits, occlusionPass(3, 0.8f));
    ASSERT_TRUE(raysShareSegment(pass.rays.rays));
    for (std::size_t i = 0; i < pass.rays.rays.size(); i += 3) pass.rays.rays[i].tmax = 0.25f;
    ASSERT_FALSE(raysShareSegment(pass.rays.rays));
    const TraceResult reference = pass.trace(Backend::CpuSeq);
    std::size_t occluded = 0;
    for (const Hit& h : reference.hits) occluded += h.prim != kMissPrim;
    ASSERT_GT(occluded, 0u);
    ASSERT_LT(occluded, reference.hits.size());
    for (unsigned regions : {1u, 3u}) {
        ThreadPool pool(2);
        const TraceResult r = GpuTracer(*context, pool, gpuOptions(regions), GpuTuning{0, 2}).trace(pass.geometry);
        EXPECT_TRUE(identicalVisibility(reference.hits, r.hits)) << regions << " regions";
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, SecondaryPassesMadeOnTheDeviceMatchTheHost) {
    // The primary hits stay on the device; shaders/secondary.comp makes each pass's rays there
    // (the host's code, bit for bit) and bins them; the visibility of every slot equals the
    // host-made pass traced by cpu-seq, and so do the slots without a ray.
    DACRT_REQUIRE_GPU(context);
    CameraOptions view;
    view.eye = glm::dvec3(-1.0, 2.0, 4.0);
    const Frame frame(shapes(), 40, 30, view);
    const SecondaryPass directional = directionalShadowPass({0.4, -1.0, -0.3});
    // The last configuration reaches every array by address, in chunks of 4032 bytes.
    std::vector<std::pair<unsigned, GpuTuning>> configurations = {{1, GpuTuning{0, 1}}, {1, GpuTuning{0, 2}}, {3, GpuTuning{0, 1}},
                                                                   {3, GpuTuning{0, 2}}};
    if (context->info().bufferDeviceAddress) configurations.push_back({3, GpuTuning{.rayGroups = 2, .bufferBytes = 4096, .chunkBytes = 4096}});
    for (const auto& [regions, tuning] : configurations) {
        const std::uint32_t groups = tuning.rayGroups;
        const TraceOptions o = gpuOptions(regions);
        ThreadPool pool(2);
        GpuPassSourcePtr source;
        GpuTracer tracer(*context, pool, o, tuning);
        const TraceResult primary = tracer.trace(frame.geometry, {}, &source);
        ASSERT_TRUE(source);
        for (const SecondaryPass& p : {occlusionPass(3, 0.8f), pointShadowPass({0.3f, 1.6f, 0.4f}), directional}) {
            SCOPED_TRACE(p.name + ", " + std::to_string(regions) + " regions, " + std::to_string(groups) + " groups");
            const PassFrame host(frame, primary.hits, p);
            const std::vector<Hit> expected = hitsPerSlot(host.rays, host.trace(Backend::CpuSeq).hits);
            const TraceResult device = tracer.traceSecondary(*source, frame.geometry, p);
            ASSERT_EQ(device.hits.size(), expected.size());
            std::size_t notTraced = 0, occluded = 0;
            for (std::size_t i = 0; i < expected.size(); ++i) {
                ASSERT_EQ(device.hits[i].prim == kNotTracedPrim, expected[i].prim == kNotTracedPrim) << "slot " << i;
                notTraced += expected[i].prim == kNotTracedPrim;
                occluded += expected[i].prim != kNotTracedPrim && expected[i].prim != kMissPrim;
            }
            EXPECT_TRUE(identicalVisibility(expected, device.hits));
            EXPECT_GT(occluded, expected.size() / 50);
            EXPECT_GT(notTraced, 0u);
        }
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, RayGroupsGiveTheSameHits) {
    // Groups split each region's rays into bands with private triangle ids; with transfer
    // rounds (camera inside, 4 regions) and with more groups than some regions have rays.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 48, 36), 48, 36);
    for (std::uint32_t groups : {1u, 3u, 5u}) expectGpuMatchesCpu(*context, frame, {1, 2, 4}, GpuTuning{.rayGroups = groups});
    const Frame inside = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2)},
                                    {0.1, 0.0, 0.2}, {0.3, 0.0, -1.0}, 40, 30);
    EXPECT_GT(expectGpuMatchesCpu(*context, inside, {4}, GpuTuning{.rayGroups = 64}), 0u) << "expected transfer rounds";
}

TEST(GpuImages, EveryLeafBalanceGivesTheSameHits) {
    // The balance decides every leaf where no limit is given (off: the limits alone): from
    // nodes split down to single rays or triangles (1) to whole regions as leaves (4096), with
    // transfer rounds; the kernel reports the rule it ran.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 48, 36), 48, 36);
    const Frame inside = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2)},
                                    {0.1, 0.0, 0.2}, {0.3, 0.0, -1.0}, 40, 30);
    std::map<std::uint32_t, std::uint64_t> tests;  // ray/triangle tests by balance
    for (std::uint32_t balance : {0u, 1u, 2u, 7u, kCpuProfileLeafBalance, 64u, kMostLeafBalance}) {
        SCOPED_TRACE("leaf balance " + std::to_string(balance));
        const GpuTuning tuning{.leafBalance = balance};
        expectGpuMatchesCpu(*context, frame, {1, 3}, tuning);
        EXPECT_GT(expectGpuMatchesCpu(*context, inside, {4}, tuning), 0u) << "expected transfer rounds";
        ThreadPool pool(2);
        const TraceResult r = GpuTracer(*context, pool, gpuOptions(2), tuning).trace(frame.geometry);
        EXPECT_EQ(r.gpu->leafBalance, balance);
        EXPECT_EQ(r.gpu->rayLimit, balance ? 1u : kGpuLeafLimit);
        tests[balance] = r.counters.rayTriangleTests;
    }
    // The kernel applies it: a larger balance makes larger leaves, so more tests (the same hits).
    EXPECT_LT(tests[1], tests[7]);
    EXPECT_LT(tests[7], tests[kCpuProfileLeafBalance]);
    EXPECT_LT(tests[kCpuProfileLeafBalance], tests[kMostLeafBalance]);
    ThreadPool pool(2);
    EXPECT_THROW(GpuTracer(*context, pool, gpuOptions(2), GpuTuning{.leafBalance = kMostLeafBalance + 1}), InputError);
}

TEST(GpuImages, EveryPacketFlushGivesTheSameHits) {
    // Packets split down to single packets (1), to the default's 16, or never (a whole
    // region's packets flushed at once), and no packets; the default also under the discrete
    // profile (many ray slots, each with its own packets); with transfer rounds. A device with
    // a loop budget (llvmpipe before Mesa 25) traces rays alone. Every flush is a pipeline of its
    // own (a specialization constant), so the list is short.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 61, 37), 61, 37);  // tiles cut at the image's edges
    const Frame inside = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2)},
                                    {0.1, 0.0, 0.2}, {0.3, 0.0, -1.0}, 40, 30);
    const bool packets = gpu::loopBudgetOf(context->info()) == 0;
    struct Case {
        std::uint32_t flush;
        GpuTuning tuning;
    };
    for (const Case& k : {Case{1u, {}}, Case{kPacketFlushDefault, {}}, Case{kPacketFlushDefault, kDiscreteProfile},
                          Case{100000u, {}}}) {
        SCOPED_TRACE("packet flush " + std::to_string(k.flush) + (k.tuning.profile == GpuProfile::Discrete ? ", discrete" : ""));
        const DacrtOptions dacrt{.packetFlush = k.flush};
        expectGpuMatchesCpu(*context, frame, {1, 3}, k.tuning, dacrt);
        EXPECT_GT(expectGpuMatchesCpu(*context, inside, {4}, k.tuning, dacrt), 0u) << "expected transfer rounds";
        TraceOptions o = gpuOptions(2);
        o.dacrt = dacrt;
        ThreadPool pool(2);
        const TraceResult r = GpuTracer(*context, pool, o, k.tuning).trace(frame.geometry);
        EXPECT_EQ(r.counters.packetBoxTests > 0, packets);
        EXPECT_EQ(r.gpu->packets > 0, packets);
        EXPECT_EQ(r.gpu->packetFlush, packets ? k.flush : 0u);
    }
    TraceOptions off = gpuOptions(2);
    off.dacrt.packets = false;
    expectGpuMatchesCpu(*context, frame, {1, 3}, {}, off.dacrt);
    ThreadPool pool(2);
    const TraceResult r = GpuTracer(*context, pool, off, {}).trace(frame.geometry);
    EXPECT_EQ(r.counters.packetBoxTests, 0u);
    EXPECT_EQ(r.gpu->packets, 0u);
    EXPECT_GT(r.counters.rayBoxTests, 0u);
}

TEST(GpuImages, TightBoxesGiveTheSameHitsAndSaveTests) {
    // The kernel's tight node boxes (tightenBox, shaders/dacrt.comp) on the cpu backends' scene
    // for them (support/tight_box_scene.hpp): rays of their own origins at and along the
    // clusters' bounds' faces, closest and any hit, and a camera's rays (packets where the device
    // allows them), on one and three regions, with the boxes and without. cpu-seq's hits bit for
    // bit (any hit: the visibility), boxes shrunk and fewer ray/triangle tests with them.
    DACRT_REQUIRE_GPU(context);
    const TightBoxScene scene = tightBoxScene();
    const Scene s = sceneFromMeshes(scene.meshes);
    const std::vector<Bounds> bounds = allTriangleBounds(s.triangles);
    for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
        SCOPED_TRACE(query == HitQuery::Any ? "any hit" : "closest hit");
        FrameGeometry g = frameGeometry(s.triangles, bounds, scene.rays, sceneBounds(s.triangles));
        g.query = query;
        const TraceResult reference = traceFrame(g, Backend::CpuSeq);
        // Workgroups of several subgroups too, whose bounds meet through shared memory: with the
        // boxes only, as that meeting is what they test (without the boxes they would add two
        // kernel variants, over a minute of compile on Mesa 25.0.7 with a clean shader cache).
        const std::uint32_t severalSubgroups = 4 * context->info().subgroupSize;
        for (const GpuTuning& tuning : {GpuTuning{}, GpuTuning{.workgroupSize = severalSubgroups}})
            for (unsigned regions : {1u, 3u}) {
                SCOPED_TRACE(std::to_string(regions) + " regions, workgroup " + std::to_string(tuning.workgroupSize));
                const bool severalSubgroupsWorkgroup = tuning.workgroupSize != 0;
                std::map<bool, Counters> counters;  // by tight boxes on
                for (bool tight : {true, false}) {
                    if (!tight && severalSubgroupsWorkgroup) continue;
                    TraceOptions o = gpuOptions(regions);
                    o.dacrt.tightBoxes = tight;
                    ThreadPool pool(2);
                    const TraceResult r = GpuTracer(*context, pool, o, tuning).trace(g);
                    EXPECT_TRUE(query == HitQuery::Closest ? identicalHits(reference.hits, r.hits)
                                                           : identicalVisibility(reference.hits, r.hits))
                        << "tight boxes " << tight;
                    counters[tight] = r.counters;
                }
                EXPECT_GT(counters[true].tightBoxes, 0u);
                if (severalSubgroupsWorkgroup) continue;
                EXPECT_EQ(counters[false].tightBoxes, 0u);
                EXPECT_LT(counters[true].rayTriangleTests, counters[false].rayTriangleTests);
            }
    }
    CameraOptions view;
    view.eye = scene.cameraEye;
    view.target = glm::dvec3(0.0);
    const Frame frame(sceneFromMeshes(scene.meshes), 64, 64, view);
    std::map<bool, Counters> counters;  // by tight boxes on
    for (bool tight : {true, false}) {
        SCOPED_TRACE(tight ? "camera, tight boxes" : "camera, cells");
        expectGpuMatchesCpu(*context, frame, {1, 3}, {}, DacrtOptions{.tightBoxes = tight});
        TraceOptions o = gpuOptions(1);
        o.dacrt.tightBoxes = tight;
        ThreadPool pool(2);
        counters[tight] = GpuTracer(*context, pool, o, {}).trace(frame.geometry).counters;
    }
    EXPECT_GT(counters[true].tightBoxes, 0u) << "camera";
    EXPECT_EQ(counters[false].tightBoxes, 0u) << "camera";
    EXPECT_LT(counters[true].rayTriangleTests, counters[false].rayTriangleTests) << "camera";
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, CameraInsideTheSceneAndOnSplitPlanes) {
    DACRT_REQUIRE_GPU(context);
    // The eye is inside, and on the x = 0 and y = 0 planes.
    const Frame frame = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2),
                                    torus({-1.0f, -0.5f, 1.5f}, 0.6f, 0.2f, 24, 12)},
                                   {0.0, 0.0, 0.2}, {0.3, 0.0, -1.0}, 64, 48);
    expectGpuMatchesCpu(*context, frame, {1, 2, 4, 8});
}

TEST(GpuImages, NearlyCoincidentWallsAcrossASplitPlane) {
    DACRT_REQUIRE_GPU(context);
    const float below = std::nextafter(1.0f, 0.0f), above = std::nextafter(1.0f, 2.0f);
    const Frame frame = insideView({grid({below, -4, -4}, {0, 8, 0}, {0, 0, 8}, 9, 7),
                                    grid({above, -4, -4}, {0, 8, 0}, {0, 0, 8}, 7, 9),
                                    grid({0, -4, -4}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1),
                                    grid({2, 3.9f, 3.9f}, {0, 0.1f, 0}, {0, 0, 0.1f}, 1, 1)},
                                   {0.3, 0.1, 0.2}, {1.0, 1.5, -2.0}, 96, 72);
    expectGpuMatchesCpu(*context, frame, {1, 2, 4, 8, 16});
}

TEST(GpuImages, StanfordBunny) {
    DACRT_REQUIRE_GPU(context);
    DACRT_REQUIRE_SHARED_SCENE(path, "bunny.glb");
    Scene s = loadGltf(path);
    const Camera cam = defaultCamera(s, 160, 120);
    const Frame frame(std::move(s), cam, 160, 120);
    expectGpuMatchesCpu(*context, frame, {1, 2, 4, 8, 16, 64});
}

TEST(GpuImages, DiscreteProfileGivesCpuSeqHitsOnTheTestScenes) {
    // A discrete GPU's defaults forced on any device (lavapipe here): kDiscreteRegions regions
    // with their ray groups, at least kDiscreteStep1WorkItems work items in Step 1 (most of them
    // empty on frames this small), wide workgroups; the same hits bit for bit.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 96, 72), 96, 72);
    EXPECT_GT(expectGpuMatchesCpu(*context, frame, {0}, kDiscreteProfile), 0u);
    const Frame inside = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2),
                                     torus({-1.0f, -0.5f, 1.5f}, 0.6f, 0.2f, 24, 12)},
                                    {0.0, 0.0, 0.2}, {0.3, 0.0, -1.0}, 64, 48);
    EXPECT_GT(expectGpuMatchesCpu(*context, inside, {0}, kDiscreteProfile), 0u);
    if (const std::string bunny = sharedScene("bunny.glb"); !bunny.empty()) {
        Scene loaded = loadGltf(bunny);
        const Camera cam = defaultCamera(loaded, 160, 120);
        EXPECT_GT(expectGpuMatchesCpu(*context, Frame(std::move(loaded), cam, 160, 120), {0}, kDiscreteProfile), 0u);
    }
    ThreadPool pool(2);
    const TraceResult r = GpuTracer(*context, pool, gpuOptions(0), kDiscreteProfile).trace(frame.geometry);
    EXPECT_EQ(r.regions, gpu::kDiscreteRegions);
    // Every group asked for is given, shared out among the regions by estimated cost.
    EXPECT_EQ(r.gpu->workPasses.front().items, r.regions * r.gpu->rayGroups);
    EXPECT_GE(r.gpu->workPasses.front().items, gpu::kDiscreteStep1WorkItems);
    EXPECT_EQ(r.gpu->workgroupSize, std::max(64u, context->info().subgroupSize));
}

TEST(GpuImages, WorkItemCostsAreTheSameInEveryRun) {
    // The report's costs come from the kernel's cost model, not from timings: a frame traced
    // again gives the same spread; the profiles shape the work items differently.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 96, 72), 96, 72);
    ThreadPool pool(2);
    auto spread = [&](const GpuTuning& tuning) {
        const TraceResult r = GpuTracer(*context, pool, gpuOptions(0), tuning).trace(frame.geometry);
        std::vector<std::uint64_t> costs{r.gpu->workCost, r.gpu->longestChainCost};
        for (const GpuWorkPass& p : r.gpu->workPasses) costs.insert(costs.end(), {p.items, p.maxCost});
        return costs;
    };
    const GpuTuning cpuProfile{.profile = GpuProfile::Cpu};
    EXPECT_EQ(spread(cpuProfile), spread(cpuProfile));
    EXPECT_EQ(spread(kDiscreteProfile), spread(kDiscreteProfile));
    EXPECT_NE(spread(cpuProfile), spread(kDiscreteProfile));
}

TEST(GpuImages, SlicedWorkItemsMatchTheUnslicedOnes) {
    // A tiny workgroup on one region forces many slices on llvmpipe (and none elsewhere):
    // resuming from saved state must give the same hits.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 128, 96), 128, 96);
    TraceOptions o;
    o.backend = Backend::Gpu;
    o.regions = 1;
    ThreadPool pool(1);
    const TraceResult r = GpuTracer(*context, pool, o, GpuTuning{context->info().subgroupSize}).trace(frame.geometry);
    EXPECT_TRUE(identicalHits(frame.trace(Backend::CpuSeq).hits, r.hits));
    if (gpu::loopBudgetOf(context->info()) > 0) {
        EXPECT_GT(r.gpu->slices, 1u) << "expected the work item to need several slices";
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, UnknownDeviceListsTheChoices) {
    DACRT_REQUIRE_GPU(context);
    try {
        gpu::Context other(gpu::ContextOptions{"no such device 42", false});
        FAIL() << "accepted an unknown device";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("matches no Vulkan device"), std::string::npos) << what;
        EXPECT_NE(what.find(context->info().name), std::string::npos) << what;
    }
}

TEST(GpuImages, ARayBufferOverTheBindingLimitIsAddressedOrAClearError) {
    // One row more rays than one binding holds: planned by device address in chunks where the
    // device has buffer device addresses (the plan names the limit; the frame stops there),
    // refused with the limit and the excess where it has not.
    DACRT_REQUIRE_GPU(context);
    const std::uint64_t limit = context->info().maxStorageBufferRange;
    if (limit > (256ull << 20)) GTEST_SKIP() << "the device's storage buffer range is too large to exceed cheaply";
    const int width = 2048, height = int(limit / sizeof(Ray) / width) + 1;  // one row more than the ray buffer allows
    const Scene s = sceneFromMeshes({grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 1, 1)});
    const Frame frame(sceneFromMeshes({grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 1, 1)}), defaultCamera(s, width, height),
                      width, height);
    TraceOptions o;
    o.backend = Backend::Gpu;
    o.regions = 2;
    ThreadPool pool(2);
    try {
        const TraceResult r = GpuTracer(*context, pool, o, GpuTuning{}).trace(frame.geometry, [](const MemoryPlan&) { return false; });
        ASSERT_TRUE(context->info().bufferDeviceAddress)
            << "a " << frame.rays.size() * sizeof(Ray) << "-byte ray buffer was accepted without device addresses";
        const WorkLine* chunks = workLine(r.memory, "addressed chunks");
        ASSERT_NE(chunks, nullptr);
        EXPECT_NE(chunks->why.find("maxStorageBufferRange: " + std::to_string(limit)), std::string::npos) << chunks->why;
        EXPECT_NE(chunks->why.find("maxMemoryAllocationSize"), std::string::npos) << chunks->why;
    } catch (const InputError& e) {
        EXPECT_FALSE(context->info().bufferDeviceAddress) << e.what();
        const std::string what = e.what();
        EXPECT_NE(what.find("maxStorageBufferRange of " + std::to_string(limit)), std::string::npos) << what;
        EXPECT_NE(what.find("over by"), std::string::npos) << what;
    }
}

TEST(GpuImages, ArraysInAddressedChunksGiveTheSameHits) {
    // Caps of 4 KiB address every array of these small frames in chunks of 4032 bytes (84
    // triangles): with one region, chunk boundaries fall inside its triangles, bounds and ids;
    // with the camera inside, through transfer rounds and ray groups too.
    DACRT_REQUIRE_GPU(context);
    if (!context->info().bufferDeviceAddress) GTEST_SKIP() << "the device lacks bufferDeviceAddress";
    constexpr GpuTuning kSmallChunks{.bufferBytes = 4096, .chunkBytes = 4096};
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 48, 36), 48, 36);
    expectGpuMatchesCpu(*context, frame, {1}, kSmallChunks);
    const Frame inside = insideView({box({-3, -2, -4}, {3, 2, 4}), icosphere({0.5f, 0.2f, -1.5f}, 0.5f, 2)},
                                    {0.1, 0.0, 0.2}, {0.3, 0.0, -1.0}, 40, 30);
    EXPECT_GT(expectGpuMatchesCpu(*context, inside, {4}, GpuTuning{.rayGroups = 3, .bufferBytes = 4096, .chunkBytes = 4096}), 0u)
        << "expected transfer rounds";

    ThreadPool pool(2);
    const TraceResult r = GpuTracer(*context, pool, gpuOptions(1), kSmallChunks).trace(frame.geometry, [](const MemoryPlan&) { return false; });
    const WorkLine* chunks = workLine(r.memory, "addressed chunks");
    ASSERT_NE(chunks, nullptr);
    EXPECT_NE(chunks->why.find("buffer cap (GpuTuning::bufferBytes): 4096 bytes"), std::string::npos) << chunks->why;
    EXPECT_NE(chunks->why.find("4032 bytes (chunk cap (GpuTuning::chunkBytes))"), std::string::npos) << chunks->why;
    const std::uint64_t triangleChunks = (frame.scene.triangles.size() * sizeof(Triangle) + 4031) / 4032;
    EXPECT_GT(triangleChunks, 2u);
    const std::string trianglesLine = "device: triangles (" + std::to_string(triangleChunks) + " chunks)";
    EXPECT_TRUE(std::any_of(r.memory.buffers.begin(), r.memory.buffers.end(),
                            [&](const auto& b) { return b.first == trianglesLine; }))
        << r.memory.describe();
}

TEST(GpuImages, StanfordBunnyAddressed) {
    // Every array beyond a 1 MiB binding cap, and each in one chunk (the chunk cap is the
    // device's): the addressed kernel's path for arrays beyond one binding on lavapipe.
    DACRT_REQUIRE_GPU(context);
    DACRT_REQUIRE_SHARED_SCENE(path, "bunny.glb");
    if (!context->info().bufferDeviceAddress) GTEST_SKIP() << "the device lacks bufferDeviceAddress";
    Scene s = loadGltf(path);
    const Camera cam = defaultCamera(s, 64, 48);
    const Frame frame(std::move(s), cam, 64, 48);
    constexpr GpuTuning kAddressed{.bufferBytes = 1 << 20};
    expectGpuMatchesCpu(*context, frame, {4}, kAddressed);
    ThreadPool pool(2);
    const TraceResult r = GpuTracer(*context, pool, gpuOptions(4), kAddressed).trace(frame.geometry, [](const MemoryPlan&) { return false; });
    const WorkLine* chunks = workLine(r.memory, "addressed chunks");
    ASSERT_NE(chunks, nullptr);
    EXPECT_EQ(chunks->count, std::uint64_t(DACRT_ADDRESSED_ARRAYS)) << r.memory.describeWork();
}

TEST(GpuImages, AFrameBeyondTheDeviceMemoryIsRefusedBeforeAllocation) {
    // Every buffer of the frame together against the device's memory (here a cap below it):
    // refused at the plan, with the limit and the excess, before the plan hook or any upload.
    DACRT_REQUIRE_GPU(context);
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 48, 36), 48, 36);
    ThreadPool pool(2);
    bool planned = false;
    try {
        GpuTracer(*context, pool, gpuOptions(2), GpuTuning{.memoryBytes = 65536}).trace(frame.geometry, [&](const MemoryPlan&) {
            planned = true;
            return true;
        });
        FAIL() << "a frame beyond the memory cap was accepted";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("memory cap (GpuTuning::memoryBytes) of 65536 bytes (over by "), std::string::npos) << what;
    }
    EXPECT_FALSE(planned);
}

TEST(GpuImages, AFrameThatFitsOnlyWithoutPacketsIsTracedWithout) {
    // Packets lengthen the ray id buffer: under a memory cap between the frame's device bytes
    // without packets and with them, the frame is planned again without them, the same hits.
    DACRT_REQUIRE_GPU(context);
    if (gpu::loopBudgetOf(context->info()) != 0) GTEST_SKIP() << "no packets on a device with a loop budget";
    const Scene s = shapes();
    const Frame frame(shapes(), defaultCamera(s, 48, 36), 48, 36);
    auto deviceBytes = [&](bool packets) {
        TraceOptions o = gpuOptions(2);
        o.dacrt.packets = packets;
        ThreadPool pool(2);
        std::uint64_t bytes = 0;
        GpuTracer(*context, pool, o, {}).trace(frame.geometry, [&](const MemoryPlan& plan) {
            for (const auto& [name, b] : plan.buffers)
                if (name.rfind("device: ", 0) == 0) bytes += b;
            return false;  // planned only
        });
        return bytes;
    };
    const std::uint64_t without = deviceBytes(false), with = deviceBytes(true);
    ASSERT_LT(without, with);
    ThreadPool pool(2);
    const TraceResult r =
        GpuTracer(*context, pool, gpuOptions(2), GpuTuning{.memoryBytes = (without + with) / 2}).trace(frame.geometry);
    EXPECT_EQ(r.gpu->packets, 0u);
    EXPECT_EQ(r.counters.packetBoxTests, 0u);
    EXPECT_TRUE(identicalHits(frame.trace(Backend::CpuSeq).hits, r.hits));
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, TrianglesStayOnTheDeviceAcrossFramesUntilTheyChange) {
    // The uploads skip: frames of one trianglesVersion upload the triangles once, and a frame
    // whose triangles moved (a new version) uploads them again: the hits are always the ones
    // of this frame's triangles.
    DACRT_REQUIRE_GPU(context);
    Frame frame(shapes(), 48, 32, CameraOptions{});
    frame.geometry.trianglesVersion = frame.scene.trianglesVersion;
    TraceOptions o;
    o.backend = Backend::Gpu;
    o.regions = 2;
    ThreadPool pool(2);
    gpu::ResidentTriangles resident;
    auto skippedBytes = [](const TraceResult& r) {
        for (const WorkLine& w : r.memory.work)
            if (w.name.find("skipped: triangle and bounds upload") == 0) return w.count;
        return std::uint64_t(~0ull);
    };
    const TraceResult first = GpuTracer(*context, pool, o, GpuTuning{}, nullptr, &resident).trace(frame.geometry);
    const TraceResult second = GpuTracer(*context, pool, o, GpuTuning{}, nullptr, &resident).trace(frame.geometry);
    EXPECT_EQ(skippedBytes(first), 0u);
    EXPECT_EQ(skippedBytes(second), frame.scene.triangles.size() * (sizeof(Triangle) + sizeof(Bounds)));
    EXPECT_TRUE(identicalHits(frame.trace(Backend::CpuSeq).hits, first.hits));
    EXPECT_TRUE(identicalHits(first.hits, second.hits));

    // Every triangle moved along x: a new version, uploaded again.
    for (Triangle& t : frame.scene.triangles)
        for (glm::vec3* v : {&t.v0, &t.v1, &t.v2}) v->x += 0.25f;
    touchTriangles(frame.scene);
    frame.bounds = allTriangleBounds(frame.scene.triangles);
    frame.geometry = frameGeometry(frame.scene.triangles, frame.bounds, frame.rays, sceneBounds(frame.scene.triangles), 48);
    frame.geometry.trianglesVersion = frame.scene.trianglesVersion;
    const TraceResult moved = GpuTracer(*context, pool, o, GpuTuning{}, nullptr, &resident).trace(frame.geometry);
    EXPECT_EQ(skippedBytes(moved), 0u);
    EXPECT_TRUE(identicalHits(frame.trace(Backend::CpuSeq).hits, moved.hits));
    EXPECT_FALSE(identicalHits(first.hits, moved.hits)) << "the scene moved";
    o.skips.uploads = false;  // off: every frame uploads, nothing is kept
    const TraceResult off = GpuTracer(*context, pool, o, GpuTuning{}, nullptr, &resident).trace(frame.geometry);
    EXPECT_EQ(skippedBytes(off), 0u);
    EXPECT_TRUE(identicalHits(moved.hits, off.hits));
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, KeptTrianglesInChunksAFrameCannotReachAreUploadedAgainAndReportedSo) {
    // Frames of one trianglesVersion that alternate between binding the triangles whole and
    // addressing them in chunks: a frame reuses the kept buffers where it reaches them as they
    // are (Buffer::suitsChunks), else uploads them again, and its plan says which it did.
    DACRT_REQUIRE_GPU(context);
    if (!context->info().bufferDeviceAddress) GTEST_SKIP() << "the device lacks buffer device addresses";
    Frame frame(shapes(), 48, 32, CameraOptions{});
    frame.geometry.trianglesVersion = frame.scene.trianglesVersion;
    const std::uint64_t triangleBytes = frame.scene.triangles.size() * (sizeof(Triangle) + sizeof(Bounds));
    ASSERT_GT(triangleBytes, 2 * 4096u);
    const TraceResult reference = frame.trace(Backend::CpuSeq);
    const GpuTuning bound{}, smallChunks{.bufferBytes = 4096, .chunkBytes = 4096}, oneChunk{.bufferBytes = 4096};
    ThreadPool pool(2);
    gpu::ResidentTriangles resident;
    // Each frame's tuning, and whether it finds the triangles on the device.
    const std::vector<std::pair<GpuTuning, bool>> frames = {{bound, false},     {bound, true},    {smallChunks, false},
                                                            {smallChunks, true}, {oneChunk, false}, {bound, true}};
    for (std::size_t i = 0; i < frames.size(); ++i) {
        SCOPED_TRACE("frame " + std::to_string(i));
        const std::uint64_t uploadsBefore = resident.uploads();
        const TraceResult r = GpuTracer(*context, pool, gpuOptions(2), frames[i].first, nullptr, &resident).trace(frame.geometry);
        const bool skipped = resident.uploads() == uploadsBefore;
        EXPECT_EQ(skipped, frames[i].second);
        const WorkLine* line = workLine(r.memory, "skipped: triangle and bounds upload (bytes)");
        ASSERT_TRUE(line);
        EXPECT_EQ(line->count, skipped ? triangleBytes : 0u);
        EXPECT_TRUE(identicalHits(reference.hits, r.hits));
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST(GpuImages, OrthographicCameras) {
    // Rays of many origins sharing one direction (an orthographic camera): not sharing their
    // start, they are read per ray, and the near child comes from the direction's signs.
    DACRT_REQUIRE_GPU(context);
    for (const glm::dvec3 eye : {glm::dvec3(4.0, 3.0, 5.0), glm::dvec3(0.6, 0.35, 0.45)}) {  // outside; inside, oblique
        const Frame frame(shapes(), orthographicView(eye, 1.8), 64, 48);
        ASSERT_FALSE(frame.geometry.raysShareStart);
        EXPECT_TRUE(identicalHits(frame.trace(Backend::Brute, 0, 2).hits, frame.trace(Backend::CpuSeq).hits));
        expectGpuMatchesCpu(*context, frame, {1, 2, 4, 8});
    }
}
