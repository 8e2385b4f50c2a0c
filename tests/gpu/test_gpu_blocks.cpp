// The kernel's building blocks (workgroup_test.comp runs them in one workgroup) against the
// CPU on random inputs: stable partitions must match std::stable_partition exactly, and a
// leaf must produce exactly the hits of the CPU leaf.
#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "core/random.hpp"
#include "cpu/traversal.hpp"
#include "support/gpu_support.hpp"
#include "gpu/gpu_tracer.hpp"
#include "core/procedural.hpp"
#include "support/frames.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/dispatch_recorder.hpp"
#include "gpu/pipeline_cache.hpp"
#include "gpu/embedded_shaders.hpp"
#include "gpu/work_plan.hpp"
#include "gpu/work_spread.hpp"


using namespace dacrt;
using namespace dacrt::test;

namespace {

constexpr std::uint32_t kKeepCrossing = 0, kKeepFinished = 1, kKeepStill = 2, kKeepStuckHigh = 3;

struct BlockInputs {
    std::vector<Ray> rays;
    std::vector<Triangle> triangles;
    std::vector<Bounds> bounds;
    std::vector<Hit> hits;
    std::vector<std::uint32_t> rayIds, triIds;
};

// Each draw is its own statement: the order in which a constructor's arguments are evaluated
// is unspecified, and the inputs must be the same on every compiler.
glm::vec3 randomVec3(Random& random, float lo, float hi) {
    const float x = random.uniformFloat(lo, hi);
    const float y = random.uniformFloat(lo, hi);
    const float z = random.uniformFloat(lo, hi);
    return {x, y, z};
}

BlockInputs randomInputs(Random& random, std::size_t rays, std::size_t tris) {
    BlockInputs in;
    for (std::size_t i = 0; i < rays; ++i) {
        const glm::vec3 d = randomVec3(random, -1.0f, 1.0f);
        const glm::vec3 o = randomVec3(random, -0.1f, 0.1f);
        const glm::dvec3 direction(i % 9 == 0 ? 0.0 : d.x, d.y, -1.0);  // some rays with no motion along x
        in.rays.push_back(makeRay({o.x, o.y, 3.0f}, direction));
        Hit h = missHit();
        if (i % 3 == 0) h = Hit{3.0f + random.uniformFloat(-1.0f, 1.0f), std::uint32_t(i % 7), 0.1f, 0.2f};
        in.hits.push_back(h);
    }
    for (std::size_t i = 0; i < tris; ++i) {
        glm::vec3 c = randomVec3(random, -1.0f, 1.0f);
        c.z *= 0.5f;
        Triangle t{};
        t.v0 = c + randomVec3(random, -0.3f, 0.3f);
        t.v1 = c + randomVec3(random, -0.3f, 0.3f);
        t.v2 = c + randomVec3(random, -0.3f, 0.3f);
        if (i % 11 == 0) t.v2 = t.v1;  // degenerate
        in.triangles.push_back(t);
        in.bounds.push_back(triangleBounds(t));
    }
    in.rayIds.resize(rays);
    in.triIds.resize(tris);
    std::iota(in.rayIds.begin(), in.rayIds.end(), 0u);
    std::iota(in.triIds.begin(), in.triIds.end(), 0u);
    random.shuffle(in.rayIds);
    random.shuffle(in.triIds);
    return in;
}

// The push constants of one block over [begin, end) in the box [lo, hi].
WorkgroupTestPush blockPush(std::uint32_t mode, const glm::vec3& lo, const glm::vec3& hi, std::uint32_t begin,
                            std::uint32_t end) {
    WorkgroupTestPush push{};
    push.mode = mode;
    push.lo = lo;
    push.hi = hi;
    push.begin = begin;
    push.end = end;
    return push;
}

// The block's shape: its workgroup in subgroups, whether its barriers are dropped
// (kLockstepSubgroups: only a workgroup of one subgroup on a device that runs it in lockstep),
// and whether it runs under the device's loop budget (kLoopBudget, loopBudgetOf: a partition's
// run of tests unrolled, as under llvmpipe's loop limiter; without one the run is a loop).
struct BlockShape {
    std::uint32_t subgroups = 1;
    bool lockstep = false;
    bool loopBudget = false;
};

void PrintTo(const BlockShape& shape, std::ostream* os) {
    *os << shape.subgroups << " subgroups" << (shape.lockstep ? ", lockstep" : "")
        << (shape.loopBudget ? ", loop budget" : "");
}

// Runs workgroup_test.comp once over `in` and reads everything back into `in`; the scratch
// halves and the loop probe follow from the inputs.
std::uint32_t runBlock(gpu::Context& context, BlockInputs& in, WorkgroupTestPush push, std::uint32_t workgroupSize,
                       const BlockShape& shape) {
    push.rayScratchHalf = std::uint32_t(in.rayIds.size());
    push.triScratchHalf = std::uint32_t(in.triIds.size());
    push.loopProbe = 2;
    gpu::DacrtBindingSet set(context, gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
                                          .rays = in.rays.size(),
                                          .triangles = in.triangles.size(),
                                          .rayIds = in.rayIds.size(),
                                          .triangleIds = in.triIds.size(),
                                          .regions = 1,
                                          .workItems = 1,
                                          .maxDepth = 0,
                                      }));
    auto upload = [&](std::uint32_t binding, const auto& v) { set[binding].upload(v.data(), v.size() * sizeof(v[0])); };
    upload(DACRT_BINDING_RAYS, in.rays);
    upload(DACRT_BINDING_TRIANGLES, in.triangles);
    upload(DACRT_BINDING_TRIANGLE_BOUNDS, in.bounds);
    upload(DACRT_BINDING_HITS, in.hits);
    upload(DACRT_BINDING_RAY_IDS, in.rayIds);
    upload(DACRT_BINDING_TRI_IDS, in.triIds);
    const GpuCounters zero{};
    set[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    const gpu::KernelSpecialization specialization{.workgroupSize = workgroupSize,
                                                   .rayLimit = 16,
                                                   .triLimit = 16,
                                                   .maxDepth = 48,
                                                   .loopBudget = shape.loopBudget ? gpu::loopBudgetOf(context.info()) : 0u,
                                                   .lockstepSubgroups = shape.lockstep};
    gpu::ComputePipeline pipeline(context, gpu::workgroupTestSpirv(), DACRT_BINDING_COUNT, sizeof(WorkgroupTestPush),
                                  specialization.values(), "workgroup_test");
    set.bindTo(pipeline);
    gpu::DispatchRecorder recorder(context, 1);
    recorder.dispatch("block", pipeline, 1, &push);
    recorder.submitAndWait();
    set[DACRT_BINDING_HITS].download(in.hits.data(), in.hits.size() * sizeof(Hit));
    set[DACRT_BINDING_RAY_IDS].download(in.rayIds.data(), in.rayIds.size() * 4);
    set[DACRT_BINDING_TRI_IDS].download(in.triIds.data(), in.triIds.size() * 4);
    GpuCounters counters{};
    set[DACRT_BINDING_COUNTERS].download(&counters, sizeof(counters));
    EXPECT_EQ(counters.loopLimitHits, 0u) << "the driver's loop limiter cut the block short";
    return counters.testResult;
}

// Workgroup sizes in subgroups: the kernel's workgroups are whole subgroups (GpuTracer
// refuses others, and full subgroups are requested where the device can promise them).
class GpuBlocks : public ::testing::TestWithParam<BlockShape> {};

// The workgroup size of the test's shape; skips a shape wider than the tracer allows (the
// subgroup size squared: 16 on llvmpipe's 4-wide subgroups), a lockstep shape where the
// tracer would keep the barriers, and a loop budget where the tracer sets none (the unrolled
// partitions' compile took 117 s on Mesa 25.0.7, for code only a limiter's device runs).
#define DACRT_BLOCK_WORKGROUP(context, wg)                                                              \
    const std::uint32_t wg = GetParam().subgroups * (context)->info().subgroupSize;                     \
    if (wg > gpu::widestWorkgroup((context)->info()))                                                   \
        GTEST_SKIP() << "a workgroup of " << wg << " invocations is wider than the tracer allows here ("  \
                     << gpu::widestWorkgroup((context)->info()) << ")";                                 \
    if (GetParam().lockstep && !gpu::dropsBarriers((context)->info(), wg))                              \
        GTEST_SKIP() << "the device does not run a workgroup of " << wg << " invocations in lockstep";      \
    if (GetParam().loopBudget && gpu::loopBudgetOf((context)->info()) == 0)                              \
        GTEST_SKIP() << "the kernel runs under a loop budget only on a device with a loop limiter"

}  // namespace

TEST_P(GpuBlocks, RayPartitionsAreStableAndExact) {
    DACRT_REQUIRE_GPU(context);
    DACRT_BLOCK_WORKGROUP(context, wg);
    Random rng(wg);
    for (const auto& [count, begin, end] : {std::tuple{1000u, 0u, 1000u}, std::tuple{777u, 13u, 700u},
                                           std::tuple{5u, 1u, 4u}, std::tuple{300u, 150u, 150u}}) {
        for (std::uint32_t rule : {kKeepCrossing, kKeepFinished, kKeepStill, kKeepStuckHigh}) {
            BlockInputs in = randomInputs(rng, count, 4);
            const glm::vec3 lo(-0.2f, -0.5f, -0.1f), hi(0.4f, 0.3f, 0.2f);
            std::vector<std::uint32_t> expected = in.rayIds;
            auto keep = [&](std::uint32_t id) {
                const Ray& r = in.rays[id];
                const float bestT = in.hits[id].t;
                switch (rule) {
                    case kKeepCrossing: return shared::rayMayCrossCell(r, lo, hi, bestT);
                    case kKeepFinished: return in.hits[id].prim != kMissPrim && shared::hitEndsInBox(r, lo, hi, bestT);
                    case kKeepStill: return r.dir.x == 0.0f;
                    default: return r.dir.x > 0.0f && !shared::rayMayCrossCell(r, lo, hi, bestT);
                }
            };
            const auto pivot = std::stable_partition(expected.begin() + begin, expected.begin() + end, keep);
            WorkgroupTestPush push = blockPush(0, lo, hi, begin, end);
            push.rule = rule;
            push.axis = 0;
            const std::uint32_t result = runBlock(*context, in, push, wg, GetParam());
            EXPECT_EQ(result, std::uint32_t(pivot - expected.begin())) << "rule " << rule << " range " << begin << ".." << end;
            EXPECT_EQ(in.rayIds, expected) << "rule " << rule << " range " << begin << ".." << end;
        }
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

TEST_P(GpuBlocks, TrianglePartitionsAreStableAndExact) {
    DACRT_REQUIRE_GPU(context);
    DACRT_BLOCK_WORKGROUP(context, wg);
    Random rng(100 + wg);
    for (const auto& [count, begin, end] : {std::tuple{2000u, 0u, 2000u}, std::tuple{501u, 7u, 499u}, std::tuple{3u, 0u, 3u}}) {
        BlockInputs in = randomInputs(rng, 4, count);
        const glm::vec3 lo(-0.3f, -0.2f, -1.0f), hi(0.1f, 0.6f, 1.0f);
        std::vector<std::uint32_t> expected = in.triIds;
        const auto pivot = std::stable_partition(expected.begin() + begin, expected.begin() + end, [&](std::uint32_t id) {
            return shared::boundsOverlap(in.bounds[id].lo, in.bounds[id].hi, lo, hi);
        });
        const std::uint32_t result = runBlock(*context, in, blockPush(1, lo, hi, begin, end), wg, GetParam());
        EXPECT_EQ(result, std::uint32_t(pivot - expected.begin()));
        EXPECT_EQ(in.triIds, expected);
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

namespace {

Camera smallCamera() {
    Camera camera;
    camera.eye = glm::dvec3(0.1, 0.2, 3.0);
    camera.yfovRadians = 0.8;
    return camera;
}

}  // namespace

TEST(GpuBlocks, PrimaryRaysShareTheirStart) {
    std::vector<Ray> rays = primaryRays(smallCamera(), 8, 6);
    EXPECT_TRUE(raysShareStart(rays));
    rays[17].origin.y = std::nextafter(rays[17].origin.y, 10.0f);
    EXPECT_FALSE(raysShareStart(rays)) << "one origin a unit in the last place away";
    rays = primaryRays(smallCamera(), 8, 6);
    rays[40].tmin = 1e-6f;
    EXPECT_FALSE(raysShareStart(rays)) << "one tmin differs";
}

TEST(GpuBlocks, RaysShareTheirSegmentOnlyWithEveryTminAndTmaxAlike) {
    std::vector<Ray> rays = primaryRays(smallCamera(), 8, 6);
    EXPECT_TRUE(raysShareSegment(rays));
    rays[5].origin.x += 1.0f;
    EXPECT_TRUE(raysShareSegment(rays)) << "origins do not matter";
    rays[23].tmax = std::nextafter(rays[23].tmax, 0.0f);
    EXPECT_FALSE(raysShareSegment(rays)) << "one tmax a unit in the last place shorter";
    rays = primaryRays(smallCamera(), 8, 6);
    rays[40].tmin = 1e-6f;
    EXPECT_FALSE(raysShareSegment(rays)) << "one tmin differs";
    EXPECT_FALSE(raysShareSegment({})) << "no rays";
}

TEST_P(GpuBlocks, LeavesMatchTheCpuLeafExactly) {
    DACRT_REQUIRE_GPU(context);
    DACRT_BLOCK_WORKGROUP(context, wg);
    Random rng(200 + wg);
    // Few rays and many triangles (lanes share a ray and reduce their bests), many rays and few
    // triangles, and both; `copies` > 0 repeats that many triangles throughout, so that equal
    // t from different lanes must go to the smaller primitive id.
    for (const auto& [rays, tris, copies] : {std::tuple{3u, 500u, 0u}, std::tuple{200u, 5u, 0u}, std::tuple{50u, 70u, 0u},
                                             std::tuple{1u, 1u, 0u}, std::tuple{2u, 37u, 3u}, std::tuple{1u, 29u, 2u},
                                             std::tuple{20u, 45u, 4u}}) {
        BlockInputs in = randomInputs(rng, rays + 4, tris + 3);
        const glm::vec3 lo(-1.5f, -1.5f, -1.0f), hi(1.5f, 1.5f, 0.1f);
        const std::uint32_t begin = 2, end = 2 + rays, triBegin = 1, triEnd = 1 + tris;
        if (copies > 0) {  // every leaf ray aimed at the centre of triangle 1 (0 is degenerate), which has copies
            for (std::size_t j = copies; j < in.triangles.size(); ++j) in.triangles[j] = in.triangles[j % copies];
            const Triangle& t = in.triangles[1];
            const glm::dvec3 centre = (glm::dvec3(t.v0) + glm::dvec3(t.v1) + glm::dvec3(t.v2)) / 3.0;
            for (std::uint32_t k = begin; k < end; ++k) {
                const std::uint32_t id = in.rayIds[k];
                in.rays[id] = makeRay(in.rays[id].origin, centre - glm::dvec3(in.rays[id].origin));
                in.hits[id] = missHit();
            }
        }
        std::vector<Hit> expectedHits = in.hits;
        std::vector<std::uint32_t> expectedIds = in.rayIds;
        for (std::uint32_t k = begin; k < end; ++k) {
            const std::uint32_t id = in.rayIds[k];
            for (std::uint32_t j = triBegin; j < triEnd; ++j)
                testTriangle(in.rays[id], in.triangles[in.triIds[j]], in.triIds[j], expectedHits[id]);
        }
        const auto pivot = std::stable_partition(expectedIds.begin() + begin, expectedIds.begin() + end, [&](std::uint32_t id) {
            return expectedHits[id].prim != kMissPrim && shared::hitEndsInBox(in.rays[id], lo, hi, expectedHits[id].t);
        });
        WorkgroupTestPush push = blockPush(2, lo, hi, begin, end);
        push.triBegin = triBegin;
        push.triEnd = triEnd;
        const std::uint32_t result = runBlock(*context, in, push, wg, GetParam());
        std::size_t differing = 0;
        for (std::size_t i = 0; i < in.hits.size(); ++i)
            differing += in.hits[i].prim != expectedHits[i].prim || in.hits[i].t != expectedHits[i].t ||
                         in.hits[i].u != expectedHits[i].u || in.hits[i].v != expectedHits[i].v;
        EXPECT_EQ(differing, 0u) << rays << " rays x " << tris << " triangles";
        EXPECT_EQ(result, std::uint32_t(pivot - expectedIds.begin()));
        EXPECT_EQ(in.rayIds, expectedIds);
        std::size_t hitsFound = 0;
        for (std::uint32_t k = begin; k < end; ++k) hitsFound += expectedHits[in.rayIds[k]].prim != kMissPrim;
        if (rays >= 50 || copies > 0) {
            EXPECT_GT(hitsFound, 0u) << "the leaf should hit something";
        }
    }
    EXPECT_TRUE(noValidationErrors(*context));
}

INSTANTIATE_TEST_SUITE_P(WorkgroupSizes, GpuBlocks,
                         ::testing::Values(BlockShape{1, false}, BlockShape{4, false}, BlockShape{8, false},
                                           BlockShape{1, true}, BlockShape{1, false, true}),
                         [](const ::testing::TestParamInfo<BlockShape>& info) {
                             return "subgroups" + std::to_string(info.param.subgroups) +
                                    (info.param.lockstep ? "Lockstep" : "") +
                                    (info.param.loopBudget ? "LoopBudget" : "");
                         });

TEST(GpuBlocks, TheLongestChainFollowsTheWorkItemsThatWaitForEachOther) {
    // Three slots; Step 1, then round a (0 -> 1, 1 -> 2), then round b (0 -> 2). An item waits
    // for the latest earlier items on its ray slot and on its triangle slot.
    gpu::WorkPlan work;
    work.slots.resize(3);
    for (const auto& [rays, tris] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}})
        work.items.push_back(WorkItem{rays, tris, 0, 0, 0, 0, 0, 0});
    work.passes = {{"step1", 3}, {"a", 2}, {"b", 1}};
    const std::vector<std::uint32_t> costs{5, 3, 4, 2, 1, 7};
    // 0 -> 1 starts after item 0 (5), ends at 7; 1 -> 2 after item 2 (4), ends at 5; 0 -> 2 after 7.
    EXPECT_EQ(gpu::longestChainCost(work, costs), 14u);
    EXPECT_EQ(gpu::longestChainCost(work, std::vector<std::uint32_t>(6, 1)), 3u);
    GpuReport report;
    gpu::reportWorkSpread(work, costs, report);
    ASSERT_EQ(report.workPasses.size(), 3u);
    EXPECT_EQ(report.workPasses[0].items, 3u);
    EXPECT_EQ(report.workPasses[0].maxCost, 5u);
    EXPECT_DOUBLE_EQ(report.workPasses[0].meanCost, 4.0);
    EXPECT_EQ(report.workPasses[1].maxCost, 2u);
    EXPECT_DOUBLE_EQ(report.workPasses[1].meanCost, 1.5);
    EXPECT_EQ(report.workPasses[2].name, "b");
    EXPECT_EQ(report.workCost, 22u);
    EXPECT_EQ(report.longestChainCost, 14u);
    MemoryPlan plan;
    gpu::addWorkItemLines(work, plan);
    ASSERT_EQ(plan.work.size(), 5u);
    EXPECT_EQ(plan.work[1].name, "gpu work items: step1");
    EXPECT_EQ(plan.work[4].count, 3u);
}
