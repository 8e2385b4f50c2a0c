// Occlusion and shadow passes made and traced in groups side by side (made_pass_groups.hpp):
// which passes go that way, how the primary rays are cut into groups, that each group's worker
// makes the rays makeSecondaryRays makes and writes brute force's visibility to every slot, and
// that a shadow pass's cull, taken from the groups' surveys, keeps what the cull of its array
// keeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "core/thread_pool.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/made_pass_groups.hpp"
#include "cpu/pass_cull.hpp"
#include "cpu/ray_grouping.hpp"
#include "support/frames.hpp"

namespace dacrt {
namespace {

using namespace test;

// Primary hits of n rays, ray i hitting a surface where sends(i), else missing.
template <typename Sends>
std::vector<Hit> primaryHitsWhere(std::size_t n, Sends sends) {
    std::vector<Hit> hits(n);
    for (std::size_t i = 0; i < n; ++i) hits[i] = Hit{1.0f, sends(i) ? 0u : kMissPrim, 0.0f, 0.0f};
    return hits;
}

// Every primary ray in exactly one group, in order, each group's rays so far counted exactly,
// every group but the last making rays, and each group cut at the first ray that reaches its
// batch's start.
void expectGroupsCutAtTheBatches(const MadeGroups& groups, const std::vector<Hit>& hits, const SecondaryPass& pass,
                                 const std::vector<std::size_t>& batchStarts) {
    ASSERT_GE(groups.first.size(), 2u);
    ASSERT_EQ(groups.raysBefore.size(), groups.first.size());
    EXPECT_EQ(groups.first.front(), 0u);
    EXPECT_EQ(groups.first.back(), hits.size());
    std::size_t rays = 0, k = 0;
    for (std::size_t i = 0; i <= hits.size(); ++i) {
        if (k < groups.first.size() && groups.first[k] == i) {
            EXPECT_EQ(groups.raysBefore[k], rays) << "group " << k;
            ++k;
        }
        if (i < hits.size()) rays += hitSendsRays(hits[i]) ? pass.raysPerHit : 0;
    }
    EXPECT_EQ(k, groups.first.size());  // the starts strictly increase
    for (std::size_t g = 0; g + 1 < groups.count(); ++g) EXPECT_GT(groups.raysAtMost(g), 0u) << "group " << g;
    // A group starts at the ray after the one whose rays first reach a batch's start.
    for (std::size_t g = 1; g < groups.count(); ++g) {
        const std::size_t before = groups.raysBefore[g] - (hitSendsRays(hits[groups.first[g] - 1]) ? pass.raysPerHit : 0);
        const auto batch = std::upper_bound(batchStarts.begin(), batchStarts.end(), before);
        ASSERT_NE(batch, batchStarts.end());
        EXPECT_LE(*batch, groups.raysBefore[g]) << "group " << g << " starts past its batch";
    }
}

TEST(MadePassGroups, GroupsCutThePrimaryRaysWhereTheBatchesCutTheirRays) {
    ThreadPool pool(2);
    const SecondaryPass pass = occlusionPass(4, 0.8f);
    // Every ray of a 640x480 image hitting: 1,228,800 rays in batches of passBatchRays(1000) =
    // 65,536 for two workers: rayBatches gives 20, a group each.
    const std::vector<Hit> every = primaryHitsWhere(307200, [](std::size_t) { return true; });
    const PassRayCounts counts = passRayCounts(pass, every, pool);
    const std::vector<std::size_t> batches = rayBatches(counts.total(), passBatchRays(1000), 2);
    const MadeGroups groups = madeGroups(counts, every, pass.raysPerHit, 1000, 2);
    EXPECT_EQ(groups.count(), batches.size() - 1);
    expectGroupsCutAtTheBatches(groups, every, pass, batches);
    // An object in the middle of the image: the first and last groups hold the misses before
    // and after it (whose slots they fill), the cut lies among its rays.
    const std::vector<Hit> middle = primaryHitsWhere(307200, [](std::size_t i) { return i >= 100000 && i < 110000 && i % 3; });
    const PassRayCounts middleCounts = passRayCounts(pass, middle, pool);
    const std::vector<std::size_t> middleBatches = rayBatches(middleCounts.total(), passBatchRays(1000), 2);
    const MadeGroups cut = madeGroups(middleCounts, middle, pass.raysPerHit, 1000, 2);
    EXPECT_EQ(cut.count(), 2u);
    expectGroupsCutAtTheBatches(cut, middle, pass, middleBatches);
    // Ten primary rays for four workers: four groups within one chunk of the counts.
    const std::vector<Hit> few = primaryHitsWhere(10, [](std::size_t i) { return i != 4; });
    const PassRayCounts fewCounts = passRayCounts(pass, few, pool);
    ASSERT_EQ(fewCounts.chunks, 1u);
    const MadeGroups fewGroups = madeGroups(fewCounts, few, pass.raysPerHit, 1000, 4);
    EXPECT_EQ(fewGroups.count(), 4u);
    expectGroupsCutAtTheBatches(fewGroups, few, pass, rayBatches(fewCounts.total(), passBatchRays(1000), 4));
}

TEST(MadePassGroups, TakesOcclusionAndShadowBatchesOnCpuWorkersThatNoGridOrSubtreeTakes) {
    TraceOptions options;
    options.backend = Backend::Cpu;
    options.dacrt.rayGrouping = RayGrouping::Batches;
    const SecondaryPass occlusion = occlusionPass(4, 0.8f);
    EXPECT_TRUE(tracesMadeSideBySide(occlusion, 300000, 12000, options, 2));
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 300000, 12000, options, 1));  // one worker
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 1, 12000, options, 2));       // one ray
    // Shadow passes too: their cull's back-face tests read the groups' surveys.
    EXPECT_TRUE(tracesMadeSideBySide(pointShadowPass({0.0f, 1.0f, 0.0f}), 300000, 12000, options, 2));
    EXPECT_TRUE(tracesMadeSideBySide(directionalShadowPass({0.2, -1.0, -0.1}), 300000, 12000, options, 2));
    EXPECT_FALSE(tracesMadeSideBySide(pointShadowPass({0.0f, 1.0f, 0.0f}), 200000, 300000, options, 2));
    // Fewer rays than triangles: subtrees (cpuTracesAsSubtrees) ...
    ASSERT_TRUE(cpuTracesAsSubtrees(200000, 300000, HitQuery::Any, options, 2));
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 200000, 300000, options, 2));
    // ... or so few that the pass cull's grid pays for itself.
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 1000, 100000, options, 2));
    TraceOptions other = options;
    other.regions = 3;
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 300000, 12000, other, 2));
    other = options;
    other.backend = Backend::CpuSeq;
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 300000, 12000, other, 2));
    other = options;
    other.dacrt.rayGrouping = RayGrouping::Slots;
    EXPECT_FALSE(tracesMadeSideBySide(occlusion, 300000, 12000, other, 2));
}

// Brute force's answer per slot, from the rays makeSecondaryRays makes (how many: rays).
std::vector<Hit> bruteForcePerSlot(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                                   const SecondaryPass& pass, ThreadPool& pool, std::uint64_t& rays) {
    const SecondaryRays made = makeSecondaryRays(pass, *primary.rays, primaryHits, *primary.triangles, pool);
    rays = made.rays.size();
    const TraceResult brute = traceBrute(passFrame(primary, made.rays), pool);
    return hitsPerSlot(made, brute.hits, &pool);
}

// The slots brute force's: the same size, the same visibility, untraced where it is.
void expectBruteForcesSlots(const std::vector<Hit>& reference, const std::vector<Hit>& slots) {
    ASSERT_EQ(slots.size(), reference.size());
    EXPECT_TRUE(identicalVisibility(reference, slots));
    std::size_t untracedApart = 0;
    for (std::size_t i = 0; i < reference.size(); ++i)
        untracedApart += (reference[i].prim == kNotTracedPrim) != (slots[i].prim == kNotTracedPrim);
    EXPECT_EQ(untracedApart, 0u);
}

// The rays and slots makeSecondaryRays' array holds, bit for bit.
void expectTheArray(const SecondaryRays& rays, const SecondaryRays& array) {
    EXPECT_EQ(rays.slotCount, array.slotCount);
    EXPECT_EQ(rays.slots, array.slots);
    ASSERT_EQ(rays.rays.size(), array.rays.size());
    EXPECT_EQ(std::memcmp(rays.rays.data(), array.rays.data(), array.rays.size() * sizeof(Ray)), 0);
}

// A pass made and traced on the pool's workers, its plans kept, beside brute force's answer per
// slot and the rays makeSecondaryRays makes (rays).
struct MadeRun {
    std::vector<Hit> reference;
    std::uint64_t rays = 0;
    PassRayCounts counts;
    std::vector<MemoryPlan> plans;
    MadePass made;
};
MadeRun runMade(const FrameGeometry& primary, const std::vector<Hit>& primaryHits, const SecondaryPass& pass,
                const TraceOptions& options, ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, PassCull& cull) {
    MadeRun run;
    run.reference = bruteForcePerSlot(primary, primaryHits, pass, pool, run.rays);
    run.counts = passRayCounts(pass, primaryHits, pool);
    run.made = traceMadeSideBySide(primary, primaryHits, pass, run.counts, options, pool, buffers, cull,
                                   [&](const MemoryPlan& p) {
                                       run.plans.push_back(p);
                                       return true;
                                   });
    return run;
}

// The shapes' occlusion passes at 96x72.
SecondaryPassSet shapesOcclusionPasses() {
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 1.5, 4.0);
    return SecondaryPassSet("shapes", shapesScene(), camera,
                            {{"occlusion 0.8", occlusionPass(4, 0.8f)}, {"occlusion unbounded", occlusionPass(4, kNoHitT)}},
                            96, 72);
}

FrameGeometry primaryFrameOf(const SecondaryPassSet& set) {
    return frameGeometry(set.frame.scene.triangles, set.frame.bounds, set.frame.rays, sceneBounds(set.frame.scene.triangles));
}

// The cpu backend's options whose occlusion passes go made side by side.
TraceOptions madeSideBySideOptions() {
    TraceOptions options;
    options.backend = Backend::Cpu;
    options.dacrt.rayGrouping = RayGrouping::Batches;
    return options;
}

TEST(MadePassGroups, EachWorkerWritesBruteForcesVisibilityToItsSlots) {
    const SecondaryPassSet set = shapesOcclusionPasses();
    const FrameGeometry primary = primaryFrameOf(set);
    const TraceOptions options = madeSideBySideOptions();
    for (const unsigned threads : {2u, 3u, 4u}) {
        ThreadPool pool(threads);
        std::vector<MadeGroupBuffers> buffers;  // kept from pass to pass, as the dispatcher keeps them
        PassCull cull;
        for (const auto& [name, pass] : set.passes) {
            SCOPED_TRACE(name + ", " + std::to_string(threads) + " threads");
            const MadeRun run = runMade(primary, set.primary.hits, pass, options, pool, buffers, cull);
            const PassRayCounts& counts = run.counts;
            const std::vector<MemoryPlan>& plans = run.plans;
            const MadePass& made = run.made;
            ASSERT_TRUE(tracesMadeSideBySide(pass, counts.total(), primary.triangles->size(), options, threads));
            EXPECT_EQ(made.rays, run.rays);
            expectBruteForcesSlots(run.reference, made.result.hits);
            // The plans: what is made, then the trace, whose last line counts the groups.
            ASSERT_EQ(plans.size(), 2u);
            const std::size_t groups = madeGroups(counts, set.primary.hits, pass.raysPerHit, primary.triangles->size(), threads).count();
            EXPECT_EQ(groups, threads);  // fewer rays than a batch: a group a worker
            ASSERT_FALSE(plans[1].work.empty());
            EXPECT_EQ(plans[1].work.back().name, "ray groups made and traced side by side");
            EXPECT_EQ(plans[1].work.back().count, groups);
            EXPECT_EQ(made.result.threads, threads);
            // The groups' counters summed: every ray that hit finished in its group's trace.
            std::uint64_t hit = 0;
            for (const Hit& h : made.result.hits) hit += h.prim != kMissPrim && h.prim != kNotTracedPrim;
            EXPECT_EQ(made.result.counters.finishedStep1, hit);
            EXPECT_GT(made.result.counters.leaves, 0u);
        }
    }
}

TEST(MadePassGroups, APlanRefusedMakesAndTracesNothing) {
    const SecondaryPassSet set = shapesOcclusionPasses();
    const FrameGeometry primary = primaryFrameOf(set);
    const TraceOptions options = madeSideBySideOptions();
    ThreadPool pool(2);
    std::vector<MadeGroupBuffers> buffers;
    const SecondaryPass& pass = set.passes.front().second;
    const PassRayCounts counts = passRayCounts(pass, set.primary.hits, pool);
    PassCull cull;
    for (const int refused : {0, 1}) {
        int asked = 0;
        const MadePass made = traceMadeSideBySide(primary, set.primary.hits, pass, counts, options, pool, buffers, cull,
                                                  [&](const MemoryPlan&) { return asked++ != refused; });
        EXPECT_EQ(asked, refused + 1);
        EXPECT_TRUE(made.result.hits.empty());
        EXPECT_EQ(made.rays, 0u);
        for (const MadeGroupBuffers& b : buffers) EXPECT_TRUE(b.rays.empty());
    }
}

// The shapes under a single-sided ceiling of 2 x cells x cells triangles, whose back every
// upward shadow ray meets, seen from below it.
Scene shapesUnderACeiling(int cells) {
    std::vector<Mesh> meshes = shapesMeshes();
    meshes.push_back(grid({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, cells, cells));
    return sceneFromMeshes(meshes, "shapes under a ceiling");
}
CameraOptions underTheCeiling() {
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 0.6, 4.0);
    return camera;
}
// Shadow passes toward a light above the ceiling, one among the shapes and a directional light.
std::vector<std::pair<std::string, SecondaryPass>> ceilingShadowPasses() {
    return {{"point light above the ceiling", pointShadowPass({0.3f, 2.0f, 0.4f})},
            {"point light among the shapes", pointShadowPass({0.0f, -0.2f, 0.0f})},
            {"directional light", directionalShadowPass({0.2, -1.0, -0.1})}};
}
SecondaryPassSet ceilingShadowPassSet() {
    return SecondaryPassSet("shapes under a ceiling", shapesUnderACeiling(4), underTheCeiling(), ceilingShadowPasses(),
                            160, 120);
}

TEST(MadePassGroups, AShadowPassIsCulledFromItsGroupsSurveysAndTracedWithBruteForcesVisibility) {
    const SecondaryPassSet set = ceilingShadowPassSet();
    const FrameGeometry primary = primaryFrameOf(set);
    const TraceOptions options = madeSideBySideOptions();
    SkipSwitches facesOnly;
    facesOnly.passRays = false;
    std::size_t traced = 0, droppedByFaces = 0;
    for (const unsigned threads : {2u, 3u}) {
        ThreadPool pool(threads);
        std::vector<MadeGroupBuffers> buffers;
        PassCull cull;
        for (const auto& [name, pass] : set.passes) {
            SCOPED_TRACE(name + ", " + std::to_string(threads) + " threads");
            if (!tracesMadeSideBySide(pass, passRayCounts(pass, set.primary.hits, pool).total(), primary.triangles->size(),
                                      options, threads))
                continue;
            const MadeRun run = runMade(primary, set.primary.hits, pass, options, pool, buffers, cull);
            const std::vector<MemoryPlan>& plans = run.plans;
            const MadePass& made = run.made;
            EXPECT_EQ(made.rays, run.rays);
            // The cull from the surveys keeps what the cull of the pass's array keeps.
            const SecondaryRays array = makeSecondaryRays(pass, *primary.rays, set.primary.hits, *primary.triangles, pool);
            PassCull scanned;
            cullForPass(passFrame(primary, array.rays), facesOnly, pool, scanned);
            EXPECT_EQ(cull.endShared, scanned.endShared);
            EXPECT_EQ(cull.directionShared, scanned.directionShared);
            EXPECT_EQ(cull.skips.traced, scanned.skips.traced);
            EXPECT_EQ(cull.skips.backFacing, scanned.skips.backFacing);
            if (made.unmade) {
                // Too few rays made for groups (subtrees, or the grid): the array, bit for bit.
                EXPECT_TRUE(made.result.hits.empty());
                expectTheArray(*made.unmade, array);
                continue;
            }
            ++traced;
            droppedByFaces += cull.skips.backFacing;
            expectBruteForcesSlots(run.reference, made.result.hits);
            // What is made, then (after the cull) the trace, with the cull's lines first.
            ASSERT_EQ(plans.size(), 2u);
            ASSERT_GE(plans[1].work.size(), 3u);
            EXPECT_EQ(plans[1].work[1].name, "skipped: back-facing");
            EXPECT_EQ(plans[1].work[1].count, cull.skips.backFacing);
            EXPECT_EQ(plans[1].work.back().name, "ray groups made and traced side by side");
        }
    }
    EXPECT_GT(traced, 0u) << "no shadow pass was traced in made groups: the test proves nothing";
    EXPECT_GT(droppedByFaces, 0u) << "the cull dropped no back face: the test proves little";
}

TEST(MadePassGroups, AShadowPassRefusedAtItsFirstPlanMakesNothingAndAtItsSecondTracesNothing) {
    // The plan of what is made comes before any ray; the trace's after the cull, before any trace.
    const SecondaryPassSet set = ceilingShadowPassSet();
    const FrameGeometry primary = primaryFrameOf(set);
    const TraceOptions options = madeSideBySideOptions();
    ThreadPool pool(2);
    const SecondaryPass& pass = set.passes.front().second;
    const PassRayCounts counts = passRayCounts(pass, set.primary.hits, pool);
    ASSERT_TRUE(tracesMadeSideBySide(pass, counts.total(), primary.triangles->size(), options, 2));
    for (const int refused : {0, 1}) {
        std::vector<MadeGroupBuffers> buffers;
        PassCull cull;
        int asked = 0;
        const MadePass made = traceMadeSideBySide(primary, set.primary.hits, pass, counts, options, pool, buffers, cull,
                                                  [&](const MemoryPlan&) { return asked++ != refused; });
        EXPECT_EQ(asked, refused + 1);
        EXPECT_TRUE(made.result.hits.empty());
        EXPECT_FALSE(made.unmade.has_value());
        std::size_t rays = 0;
        for (const MadeGroupBuffers& b : buffers) rays += b.rays.size();
        if (refused == 0) EXPECT_EQ(rays, 0u);
        else EXPECT_GT(rays, 0u) << "the cull needs every ray made before the trace's plan";
    }
}

TEST(MadePassGroups, AShadowPassOfFewerRaysThanItsKeptTrianglesGoesOnFromItsArray) {
    // A ceiling of 80,000 triangles that a light among the shapes sees from behind (the cull
    // keeps them), over a few thousand shadow rays: subtrees, which take the pass's array. The
    // primary hits are cpu-seq's (brute force's, faster over so many triangles).
    const Frame frame(shapesUnderACeiling(200), 128, 96, underTheCeiling());
    const std::vector<Hit> primaryHits = frame.trace(Backend::CpuSeq).hits;
    const FrameGeometry primary =
        frameGeometry(frame.scene.triangles, frame.bounds, frame.rays, sceneBounds(frame.scene.triangles));
    const TraceOptions options = madeSideBySideOptions();
    ThreadPool pool(2);
    std::vector<MadeGroupBuffers> buffers;
    PassCull cull;
    std::size_t unmade = 0;
    for (const auto& [name, pass] : ceilingShadowPasses()) {
        SCOPED_TRACE(name);
        const PassRayCounts counts = passRayCounts(pass, primaryHits, pool);
        const MadePass made = traceMadeSideBySide(primary, primaryHits, pass, counts, options, pool, buffers, cull, {});
        const SecondaryRays array = makeSecondaryRays(pass, *primary.rays, primaryHits, *primary.triangles, pool);
        const std::size_t kept = cull.skips.applied ? cull.skips.traced.size() : primary.triangles->size();
        const bool subtrees = cpuTracesAsSubtrees(array.rays.size(), kept, HitQuery::Any, options, 2);
        EXPECT_EQ(made.unmade.has_value(),
                  subtrees || passCullMayDrop(array.rays.size(), primary.triangles->size(), false, options.skips));
        if (!made.unmade) continue;
        ++unmade;
        expectTheArray(*made.unmade, array);
    }
    EXPECT_GT(unmade, 0u) << "every pass was traced in made groups: the test proves nothing";
}

}  // namespace
}  // namespace dacrt
