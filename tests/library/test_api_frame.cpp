// The public API's camera frames (Tracer::traceFrame): the primary pass as trace() gives it,
// then the shadow and occlusion passes from its hits, their plans, and the pass bounds.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "support/api_support.hpp"

namespace dacrt {
namespace {

using test::lightAndOcclusion;

std::size_t slotsWithRays(const std::vector<RayHit>& hits) {
    return std::size_t(std::count_if(hits.begin(), hits.end(), [](const RayHit& h) {
        return h.primitive != kNotTracedPrimitive;
    }));
}

// Every grouping of the passes' rays on the cpu backends (--ray-grouping), and the passes
// traced together (--pass-tracing), give the passes of `expected` (cpu-seq's, slot order) their
// visibility slot by slot; passes traced together name the pass that carries their trace.
void expectEveryGroupingGivesTheseVisibilities(const TraceScene& scene, const RayBatch& rays,
                                               const std::vector<FramePass>& passes, const FrameOutput& expected) {
    for (const RayGrouping grouping : {RayGrouping::Slots, RayGrouping::Octant, RayGrouping::OctantCalls, RayGrouping::Batches})
        for (const PassTracing tracing : {PassTracing::Apart, PassTracing::Together})
            for (const Backend backend : {Backend::Cpu, Backend::CpuSeq}) {
                if (tracing == PassTracing::Together &&
                    (grouping == RayGrouping::Octant || grouping == RayGrouping::OctantCalls))
                    continue;  // refused (checkOptionCombinations)
                TracerOptions o = test::onBackend(backend, 2);
                o.trace.dacrt.rayGrouping = grouping;
                o.trace.dacrt.passTracing = tracing;
                const FrameOutput grouped = Tracer(o).traceFrame(scene, rays, passes);
                ASSERT_EQ(grouped.passes.size(), expected.passes.size());
                for (std::size_t k = 0; k < expected.passes.size(); ++k) {
                    EXPECT_EQ(grouped.passes[k].rays, expected.passes[k].rays) << k;
                    EXPECT_TRUE(test::sameVisibility(expected.passes[k].output.hits, grouped.passes[k].output.hits))
                        << k << ", grouping " << int(grouping) << ", tracing " << int(tracing) << ", backend " << int(backend);
                    const bool together = tracing == PassTracing::Together && passes.size() > 1;
                    EXPECT_EQ(grouped.passes[k].tracedIn, together ? passes.size() - 1 : PassOutput::kTracedAlone) << k;
                }
            }
}

TEST(ApiFrame, TracesTheCameraFrameThenItsPasses) {
    const TraceScene scene = TraceScene::load(test::kRoomScene);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 80, 60);
    const std::vector<FramePass> passes = lightAndOcclusion(scene);
    Tracer cpu(test::onBackend(Backend::Cpu, 2));
    const FrameOutput frame = cpu.traceFrame(scene, rays, passes);
    EXPECT_FALSE(frame.stoppedAtPlan);
    EXPECT_TRUE(test::sameHits(frame.primary.hits, cpu.trace(scene, rays).hits));
    ASSERT_EQ(frame.passes.size(), 2u);

    const PassOutput& shadow = frame.passes[0];
    EXPECT_EQ(shadow.pass.name, "shadow: centre");
    ASSERT_EQ(shadow.output.hits.size(), rays.size());
    EXPECT_EQ(shadow.rays, slotsWithRays(shadow.output.hits));
    EXPECT_GT(shadow.rays, 0u);
    EXPECT_LE(shadow.rays, test::hitCount(frame.primary.hits));
    const PassOutput& occlusion = frame.passes[1];
    ASSERT_EQ(occlusion.output.hits.size(), 3 * rays.size());
    EXPECT_EQ(occlusion.rays, slotsWithRays(occlusion.output.hits));
    EXPECT_GT(test::hitCount(occlusion.output.hits), 0u);
    EXPECT_LT(test::hitCount(occlusion.output.hits), occlusion.rays);
    EXPECT_FALSE(occlusion.output.plan.work.empty());

    // Every pass is exact: the sequential backend makes and answers the same rays.
    const FrameOutput sequential = Tracer(test::onBackend(Backend::CpuSeq)).traceFrame(scene, rays, passes);
    ASSERT_EQ(sequential.passes.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(sequential.passes[k].rays, frame.passes[k].rays) << k;
        EXPECT_TRUE(test::sameHits(sequential.passes[k].output.hits, frame.passes[k].output.hits)) << k;
    }
    expectEveryGroupingGivesTheseVisibilities(scene, rays, passes, sequential);
    // A frame whose occlusion pass (4 rays a pixel) is cut into batches.
    const RayBatch larger = RayBatch::fromCamera(scene, {}, 200, 150);
    const std::vector<FramePass> fourSamples = lightAndOcclusion(scene, 4);
    ASSERT_GT(4 * larger.size(), std::max<std::size_t>(kPassBatchRays, kPassBatchRaysPerTriangle * scene.triangleCount()));
    expectEveryGroupingGivesTheseVisibilities(
        scene, larger, fourSamples, Tracer(test::onBackend(Backend::CpuSeq)).traceFrame(scene, larger, fourSamples));
}

TEST(ApiFrame, PlanCallbackSeesEachPassAndMayStop) {
    const TraceScene scene = TraceScene::load(test::kRoomScene);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 40, 30);
    const std::vector<FramePass> passes = lightAndOcclusion(scene);
    Tracer tracer(test::onBackend(Backend::Cpu, 2));
    std::vector<std::uint64_t> seen;
    const auto record = [&seen](bool go) {
        return [&seen, go](const FramePlan& plan) {
            seen.push_back(plan.totalBytes());
            return go;
        };
    };
    const FrameOutput stopped = tracer.traceFrame(scene, rays, passes, record(false));
    EXPECT_TRUE(stopped.stoppedAtPlan);
    EXPECT_TRUE(stopped.primary.hits.empty());
    EXPECT_TRUE(stopped.passes.empty());
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0], tracer.plan(scene, rays).totalBytes());

    seen.clear();
    const FrameOutput traced = tracer.traceFrame(scene, rays, passes, record(true));
    EXPECT_FALSE(traced.stoppedAtPlan);
    EXPECT_GE(seen.size(), 1 + passes.size());  // a pass may show more than one plan
    EXPECT_EQ(traced.passes.size(), passes.size());

    // A stop at any later plan, the passes apart and together (each pass's making plan, their
    // merging, the trace's own): the primary pass is kept, no pass is returned.
    for (const PassTracing tracing : {PassTracing::Apart, PassTracing::Together}) {
        TracerOptions o = test::onBackend(Backend::Cpu, 2);
        o.trace.dacrt.passTracing = tracing;
        Tracer passTracer(o);
        std::size_t plans = 0;
        ASSERT_FALSE(passTracer.traceFrame(scene, rays, passes, [&plans](const FramePlan&) { return ++plans, true; })
                         .stoppedAtPlan);
        ASSERT_GE(plans, tracing == PassTracing::Together ? 5u : 3u);  // primary, 2 makings, merging, trace
        for (std::size_t stopAt = 2; stopAt <= plans; ++stopAt) {
            std::size_t seenPlans = 0;
            const FrameOutput part = passTracer.traceFrame(scene, rays, passes, [&](const FramePlan&) {
                return ++seenPlans < stopAt;
            });
            EXPECT_TRUE(part.stoppedAtPlan) << "stop at plan " << stopAt << ", tracing " << int(tracing);
            EXPECT_EQ(seenPlans, stopAt);
            EXPECT_FALSE(part.primary.hits.empty());
            EXPECT_LT(part.passes.size(), passes.size()) << "stop at plan " << stopAt;
        }
    }
}

TEST(ApiFrame, PassBoundCountsEveryPossibleRay) {
    FramePass occlusion{.name = "occlusion", .kind = PassKind::Occlusion, .raysPerHit = 3, .occlusionDistance = 1.0f};
    const FramePlan bound = passPlanBound(occlusion, 4800, Backend::Cpu);
    ASSERT_FALSE(bound.work.empty());
    EXPECT_EQ(bound.work[0].name, "rays (at most)");
    EXPECT_EQ(bound.work[0].count, 3u * 4800u);
    EXPECT_NE(describeWork(bound).find("rays (at most)"), std::string::npos);
    EXPECT_NE(describeMemory(bound).find("total"), std::string::npos);
    EXPECT_GT(bound.totalBytes(), 3u * 4800u * 32u);  // a ray alone takes 32 bytes or more
}

// The bytes of the plan's buffer of that name; 0 where it has none.
std::uint64_t bytesOf(const FramePlan& plan, const std::string& name) {
    for (const FramePlan::Buffer& b : plan.memory)
        if (b.name == name) return b.bytes;
    return 0;
}

TEST(ApiFrame, CountBoundIsALowerBoundOfTheFramesPlans) {
    const TraceScene scene = TraceScene::load(test::kRoomScene);
    const RayBatch rays = RayBatch::fromCamera(scene, {}, 40, 30);
    const std::vector<FramePass> passes = lightAndOcclusion(scene);
    const FramePlan bound = frameMemoryBound(rays.size(), passes);
    ASSERT_EQ(bound.memory.size(), 2 + passes.size());
    ASSERT_FALSE(bound.work.empty());
    EXPECT_EQ(bound.work[0].count, rays.size());
    for (const Backend backend : {Backend::Cpu, Backend::CpuSeq, Backend::Brute}) {
        std::vector<FramePlan> seen;
        Tracer tracer(test::onBackend(backend, 2));
        const FrameOutput frame = tracer.traceFrame(scene, rays, passes, [&seen](const FramePlan& plan) {
            seen.push_back(plan);
            return true;
        });
        ASSERT_FALSE(frame.stoppedAtPlan) << backendName(backend);
        ASSERT_GE(seen.size(), 1 + passes.size()) << backendName(backend);
        // The primary pass's plan holds the bound's rays and hits, byte for byte.
        EXPECT_EQ(bytesOf(seen[0], "rays"), bytesOf(bound, "rays")) << backendName(backend);
        EXPECT_EQ(bytesOf(seen[0], "hits"), bytesOf(bound, "hits")) << backendName(backend);
        EXPECT_LE(bound.memory[0].bytes + bound.memory[1].bytes, seen[0].totalBytes()) << backendName(backend);
        // Each pass plans its hits per slot, the bound's line of that pass, before its rays.
        std::uint64_t planned = 0;
        for (const FramePlan& plan : seen) planned += plan.totalBytes();
        for (std::size_t k = 0; k < passes.size(); ++k) {
            const std::uint64_t slotHits = bytesOf(bound, "hits per slot: " + passes[k].name);
            EXPECT_GT(slotHits, 0u) << passes[k].name;
            EXPECT_EQ(slotHits, frame.passes[k].output.hits.size() * 16) << passes[k].name;  // a Hit: t, id, u, v
            EXPECT_TRUE(std::any_of(seen.begin() + 1, seen.end(), [&](const FramePlan& plan) {
                return bytesOf(plan, "hits per slot") == slotHits;
            })) << backendName(backend) << ", " << passes[k].name;
        }
        EXPECT_LE(bound.totalBytes(), planned) << backendName(backend);
    }
}

TEST(ApiFrame, CountBoundRefusesMoreSlotsThanAPassHolds) {
    FramePass occlusion{.name = "occlusion", .kind = PassKind::Occlusion, .raysPerHit = 1024, .occlusionDistance = 1.0f};
    EXPECT_THROW(frameMemoryBound(std::uint64_t(16384) * 16384, {occlusion}), InputError);
    EXPECT_EQ(frameMemoryBound(0, {occlusion}).totalBytes(), 0u);
}

}  // namespace
}  // namespace dacrt
