// A secondary pass's rays grouped by octant on the cpu backends (DacrtOptions::rayGrouping),
// and a frame's passes traced together (DacrtOptions::passTracing): through the dispatcher, as
// every frame's passes go, each gives brute force's visibility slot by slot.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cpu/backend_options.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/options.hpp"
#include "core/errors.hpp"
#include "core/mapped_memory.hpp"
#include "library/backend_dispatcher.hpp"
#include "library/frame_passes.hpp"
#include "support/dispatcher_passes.hpp"

namespace dacrt {
namespace {

using namespace test;

// Each pass of the set on brute force, then on cpu-seq and cpu (one region per thread, and
// three) under every grouping, through one dispatcher, as a frame's passes are traced.
void expectEveryGroupingAgrees(const SecondaryPassSet& set) {
    BackendDispatcher dispatcher({}, {Backend::Cpu});
    forEachPassAgainstBruteForce(set, dispatcher, [&](const FrameGeometry& primary, const SecondaryPass& pass,
                                                      const BackendDispatcher::PassTrace& reference) {
        BackendRequest request;
        for (RayGrouping grouping :
             {RayGrouping::Slots, RayGrouping::Octant, RayGrouping::OctantCalls, RayGrouping::Batches})
            for (auto [backend, regions] : {std::pair{Backend::CpuSeq, 0u}, {Backend::Cpu, 0u}, {Backend::Cpu, 3u}}) {
                request.trace.backend = backend;
                request.trace.threads = backend == Backend::CpuSeq ? 0 : 2;
                request.trace.regions = regions;
                request.trace.dacrt.rayGrouping = grouping;
                const BackendDispatcher::PassTrace t = dispatcher.traceSecondary(primary, set.primary.hits, pass, request);
                EXPECT_EQ(t.rays, reference.rays);
                EXPECT_TRUE(identicalVisibility(reference.result.hits, t.result.hits))
                    << toString(backend) << ", " << regions << " regions, grouping " << toString(grouping);
                const bool sorts = grouping == RayGrouping::Octant || grouping == RayGrouping::OctantCalls;
                EXPECT_EQ(t.result.phases.groupRays.has_value(), sorts);
                // cpu's groups side by side, unless regions are asked for: the batches (as many
                // as the workers here) and the octants (these rays take more than one); but every
                // ray at once where the cpu backend traces the pass as subtrees (subtrees.hpp),
                // which it does not for passes this small.
                const auto traced = std::find_if(t.result.memory.work.begin(), t.result.memory.work.end(),
                                                 [](const WorkLine& w) { return w.name == "triangles traced"; });
                ASSERT_NE(traced, t.result.memory.work.end());
                const bool whole = cpuTracesAsSubtrees(t.rays, traced->count, HitQuery::Any, request.trace, 2);
                EXPECT_FALSE(whole);
                const bool sideBySide = backend == Backend::Cpu && regions == 0 && !whole &&
                                        (grouping == RayGrouping::Batches || grouping == RayGrouping::OctantCalls);
                // Batches are made by the workers that trace them (made_pass_groups.hpp; a
                // shadow pass's after its cull, from their surveys); octants are the made
                // rays' groups.
                const bool made = sideBySide && grouping == RayGrouping::Batches;
                const std::string lineName = made ? "ray groups made and traced side by side" : "ray groups side by side";
                const auto line = std::find_if(t.result.memory.work.begin(), t.result.memory.work.end(),
                                               [&](const WorkLine& w) { return w.name == lineName; });
                EXPECT_EQ(line != t.result.memory.work.end(), sideBySide)
                    << toString(backend) << ", " << regions << " regions, grouping " << toString(grouping);
                if (sideBySide && line != t.result.memory.work.end()) {
                    if (grouping == RayGrouping::Batches) {
                        EXPECT_EQ(line->count, 2u);
                    }
                    EXPECT_GE(line->count, 2u);
                    EXPECT_EQ(t.result.threads, 2u);
                }
            }
    });
}

TEST(PassGrouping, EveryGroupingGivesBruteForcesVisibility) {
    expectEveryGroupingAgrees(shapesSecondaryPasses());
    expectEveryGroupingAgrees(shapesUnderACeilingPasses());
}

// Every pass of the set traced together, on cpu-seq and cpu (side by side, and in three
// regions), as slots and in batches: each pass gets its own rays and, slot by slot, brute
// force's visibility of it traced alone (the passes' segments end apart: occlusion rays at
// 0.8 and nowhere, shadow rays at their light). Returns the rays the passes made.
std::size_t expectTogetherAgrees(const SecondaryPassSet& set) {
    BackendDispatcher dispatcher({}, {Backend::Cpu});
    std::vector<SecondaryPass> passes;
    std::vector<BackendDispatcher::PassTrace> alone;
    forEachPassAgainstBruteForce(set, dispatcher, [&](const FrameGeometry&, const SecondaryPass& pass,
                                                      const BackendDispatcher::PassTrace& reference) {
        passes.push_back(pass);
        alone.push_back(reference);
    });
    if (passes.size() < 2) {
        ADD_FAILURE() << set.name << ": " << passes.size() << " passes, not two or more";
        return 0;
    }
    const FrameGeometry primary =
        frameGeometry(set.frame.scene.triangles, set.frame.bounds, set.frame.rays, sceneBounds(set.frame.scene.triangles));
    BackendRequest request;
    request.trace.dacrt.passTracing = PassTracing::Together;
    for (RayGrouping grouping : {RayGrouping::Slots, RayGrouping::Batches})
        for (auto [backend, regions] : {std::pair{Backend::CpuSeq, 0u}, {Backend::Cpu, 0u}, {Backend::Cpu, 3u}}) {
            SCOPED_TRACE(toString(backend) + ", " + std::to_string(regions) + " regions, grouping " + toString(grouping));
            request.trace.backend = backend;
            request.trace.threads = backend == Backend::CpuSeq ? 0 : 2;
            request.trace.regions = regions;
            request.trace.dacrt.rayGrouping = grouping;
            const std::vector<BackendDispatcher::PassTrace> together =
                dispatcher.traceSecondaryTogether(primary, set.primary.hits, passes, request);
            EXPECT_EQ(together.size(), passes.size());
            for (std::size_t p = 0; p < std::min(passes.size(), together.size()); ++p) {
                EXPECT_EQ(together[p].rays, alone[p].rays) << "pass " << p;
                EXPECT_TRUE(identicalVisibility(alone[p].result.hits, together[p].result.hits)) << "pass " << p;
                std::size_t untracedApart = 0;
                for (std::size_t s = 0; s < alone[p].result.hits.size(); ++s) {
                    const bool untraced = alone[p].result.hits[s].prim == kNotTracedPrim;
                    untracedApart += untraced;
                    EXPECT_EQ(together[p].result.hits[s].prim == kNotTracedPrim, untraced) << "pass " << p << " slot " << s;
                }
                EXPECT_GT(untracedApart, 0u);  // the misses' slots, at least
            }
            if (together.empty()) continue;
            // The shared trace's plan and phases go with the last pass.
            EXPECT_FALSE(together.back().result.memory.work.empty());
            EXPECT_TRUE(together.back().result.phases.makeRays.has_value());
        }
    std::size_t rays = 0;
    for (const BackendDispatcher::PassTrace& pass : alone) rays += pass.rays;
    return rays;
}

TEST(PassTracing, TogetherGivesEachPassBruteForcesVisibility) {
    expectTogetherAgrees(shapesSecondaryPasses());
    expectTogetherAgrees(shapesUnderACeilingPasses());
}

// The same at 160x120: an occlusion pass of more slots than a chunk of their fill (76,800
// against filledArray's 65,536) and more merged rays than a chunk of their scatter, so that
// both run in several chunks on the pool.
TEST(PassTracing, TogetherFillsAndScattersTheSlotsInSeveralChunks) {
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 1.5, 4.0);
    const SecondaryPassSet set("shapes at 160x120", shapesScene(), camera,
                               {{"occlusion 0.8", occlusionPass(4, 0.8f)},
                                {"shadow, light above", pointShadowPass({0.3f, 1.6f, 0.4f})}},
                               160, 120);
    ASSERT_GT(set.frame.rays.size() * 4, kFillChunk);
    EXPECT_GT(expectTogetherAgrees(set), kFrameScanChunk);
}

// Auto traces a frame's passes together where they make fewer rays than the scene has
// triangles; only the cpu backends do, and only with two passes or more.
TEST(PassTracing, TheRuleCountsThePassesRaysAgainstTheTriangles) {
    std::vector<Hit> hits(100, Hit{1.0f, 0, 0.0f, 0.0f});
    for (std::size_t i = 0; i < 40; ++i) hits[i].prim = kMissPrim;  // 60 surfaces send rays
    const std::vector<SecondaryPass> passes = {pointShadowPass({0.0f, 1.0f, 0.0f}), occlusionPass(4, 0.5f)};
    BackendRequest request;
    request.trace.backend = Backend::Cpu;
    EXPECT_TRUE(passesTracedTogether(passes, hits, 301, request));  // 60 x (1 + 4) rays
    EXPECT_FALSE(passesTracedTogether(passes, hits, 300, request));
    EXPECT_FALSE(passesTracedTogether({passes[1]}, hits, 1000000, request));
    request.trace.dacrt.rayGrouping = RayGrouping::OctantCalls;
    EXPECT_FALSE(passesTracedTogether(passes, hits, 1000000, request));
    request.trace.dacrt.rayGrouping = RayGrouping::Slots;
    EXPECT_TRUE(passesTracedTogether(passes, hits, 1000000, request));
    request.trace.dacrt.passTracing = PassTracing::Apart;
    EXPECT_FALSE(passesTracedTogether(passes, hits, 1000000, request));
    request.trace.dacrt.passTracing = PassTracing::Together;
    EXPECT_TRUE(passesTracedTogether(passes, hits, 1, request));
    request.trace.backend = Backend::CpuSeq;
    EXPECT_TRUE(passesTracedTogether(passes, hits, 1, request));
    for (Backend other : {Backend::Brute, Backend::Gpu, Backend::Embree}) {
        request.trace.backend = other;
        EXPECT_FALSE(passesTracedTogether(passes, hits, 1000000, request)) << toString(other);
    }
    // Together merges the passes' rays pixel by pixel: not with rays grouped by octant.
    DacrtOptions options;
    options.passTracing = PassTracing::Together;
    options.rayGrouping = RayGrouping::Octant;
    EXPECT_THROW(checkOptionCombinations(options), InputError);
    options.rayGrouping = RayGrouping::Batches;
    EXPECT_NO_THROW(checkOptionCombinations(options));
}

// A pass of more rays than one thread takes (kSequentialBelowRays) and fewer than its traced
// triangles (an 82k-triangle sphere among the shapes), in batches as the cpu backend groups
// them by default: the dispatcher traces every ray at once, as subtrees, where it would have
// traced a batch a worker; cpu-seq's visibility slot by slot, alone and with the passes together.
TEST(PassGrouping, PassesOfFewerRaysThanTrianglesAreTracedAsSubtrees) {
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesAndDenseSphere(6), 128, 96, camera);
    const TraceResult primaryHits = frame.trace(Backend::CpuSeq);
    const FrameGeometry primary =
        frameGeometry(frame.scene.triangles, frame.bounds, frame.rays, sceneBounds(frame.scene.triangles));
    BackendDispatcher dispatcher({}, {Backend::Cpu});
    const SecondaryPass occlusion = occlusionPass(4, 0.8f);
    BackendRequest request;
    request.trace.backend = Backend::CpuSeq;
    const BackendDispatcher::PassTrace reference = dispatcher.traceSecondary(primary, primaryHits.hits, occlusion, request);
    ASSERT_GE(reference.rays, kSequentialBelowRays);
    ASSERT_LT(reference.rays, frame.scene.triangles.size());
    request.trace.backend = Backend::Cpu;
    request.trace.threads = 2;
    ASSERT_EQ(request.trace.dacrt.rayGrouping, RayGrouping::Batches);
    auto subtrees = [](const TraceResult& r) {
        return std::any_of(r.memory.work.begin(), r.memory.work.end(),
                           [](const WorkLine& w) { return w.name == "subtrees side by side" && w.count > 1; });
    };
    const BackendDispatcher::PassTrace alone = dispatcher.traceSecondary(primary, primaryHits.hits, occlusion, request);
    EXPECT_TRUE(subtrees(alone.result));
    EXPECT_TRUE(identicalVisibility(reference.result.hits, alone.result.hits));
    request.trace.dacrt.passTracing = PassTracing::Together;
    const SecondaryPass shadow = pointShadowPass({0.3f, 1.6f, 0.4f});
    const std::vector<BackendDispatcher::PassTrace> together =
        dispatcher.traceSecondaryTogether(primary, primaryHits.hits, {occlusion, shadow}, request);
    ASSERT_EQ(together.size(), 2u);
    EXPECT_TRUE(subtrees(together.back().result));
    EXPECT_TRUE(identicalVisibility(reference.result.hits, together[0].result.hits));
    request.trace.backend = Backend::CpuSeq;
    request.trace.threads = 0;
    request.trace.dacrt.passTracing = PassTracing::Auto;
    EXPECT_TRUE(identicalVisibility(dispatcher.traceSecondary(primary, primaryHits.hits, shadow, request).result.hits,
                                    together[1].result.hits));
}

}  // namespace
}  // namespace dacrt
