// Any-hit passes traced as subtrees side by side (cpu/subtrees.hpp): the visibility bit of
// brute force, and for every ray that hits, the hit its own triangle gives it.
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/procedural.hpp"
#include "cpu/subtrees.hpp"
#include "cpu/traversal.hpp"
#include "support/frames.hpp"

namespace dacrt::test {
namespace {

// The shapes and a sphere of 20k triangles among them, seen small: more triangles than the
// passes have rays.
Frame denseFrame() {
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    return Frame(shapesAndDenseSphere(5), 32, 24, o);
}

// The subtrees a trace's division made (its work line; 0 without one).
std::uint64_t subtreesMade(const TraceResult& r) {
    for (const WorkLine& line : r.memory.work)
        if (line.name == "subtrees side by side") return line.count;
    return 0;
}

// Every hit of `hits` is the one its triangle gives its ray, bit for bit.
::testing::AssertionResult hitsAreTheirTrianglesOwn(const PassFrame& pass, const std::vector<Hit>& hits) {
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
        if (hits[i].prim == kMissPrim) continue;
        const Ray& ray = pass.rays.rays[i];
        Hit own = missHit(ray);
        testTriangle(ray, (*pass.geometry.triangles)[hits[i].prim], hits[i].prim, own);
        wrong += std::memcmp(&own, &hits[i], sizeof(Hit)) != 0;
    }
    if (wrong == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << wrong << " hits that their triangle does not give their ray";
}

}  // namespace

// Short and unbounded occlusion rays and shadow rays towards a light above the shapes and one
// among them, on two and three workers (a subtree may go to any of them): brute force's
// visibility, each hit its triangle's own, and the same hits on every run and with the bounds
// read from columns. (The cpu backend
// traces frames this small as one sequential DACRT: kSequentialBelowRays.)
TEST(Subtrees, GiveBruteForcesVisibilityAndTheirTrianglesHits) {
    const Frame frame = denseFrame();
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    std::vector<Bounds> bounds;
    std::vector<float> columns;
    Box box;
    ThreadPool columnPool(2);
    triangleBoundsInParallel(frame.scene.triangles, columnPool, bounds, box, &columns);
    const std::vector<std::pair<std::string, SecondaryPass>> passes{
        {"occlusion 0.8", occlusionPass(2, 0.8f)},
        {"occlusion unbounded", occlusionPass(2, kNoHitT)},
        {"shadow, light above", pointShadowPass({0.3f, 1.6f, 0.4f})},
        {"shadow, light among the shapes", pointShadowPass({0.0f, -0.2f, 0.0f})}};
    for (const auto& [name, secondary] : passes) {
        SCOPED_TRACE(name);
        const PassFrame pass(frame, primary.hits, secondary);
        ASSERT_GT(pass.geometry.triangles->size(), 10 * pass.rays.rays.size());
        const TraceResult reference = pass.trace(Backend::Brute, 0, 2);
        const std::size_t hits = hitCount(reference.hits);
        ASSERT_GT(hits, 0u);
        ASSERT_LT(hits, pass.rays.rays.size());
        for (unsigned workers : {2u, 3u}) {
            SCOPED_TRACE(std::to_string(workers) + " workers");
            ASSERT_TRUE(tracesAsSubtrees(pass.geometry, {}, workers));
            ThreadPool pool(workers);
            const TraceResult first = traceSubtrees(pass.geometry, {}, pool);
            EXPECT_TRUE(identicalVisibility(reference.hits, first.hits));
            EXPECT_TRUE(hitsAreTheirTrianglesOwn(pass, first.hits));
            EXPECT_EQ(first.counters.finishedStep1, hits);
            EXPECT_GT(subtreesMade(first), 1u) << "the division split the root";
            const TraceResult again = traceSubtrees(pass.geometry, {}, pool);
            EXPECT_TRUE(identicalHits(first.hits, again.hits)) << "the first subtree in the recursion's order gives the hit";
            FrameGeometry withColumns = pass.geometry;
            withColumns.boundsColumns = &columns;
            EXPECT_TRUE(identicalHits(first.hits, traceSubtrees(withColumns, {}, pool).hits)) << "bounds read from columns";
        }
    }
}

// Only any-hit frames with more triangles than rays, on the default options' SIMD path and
// spatial median, on more than one worker; traceSubtrees refuses the others.
TEST(Subtrees, TakeOnlyAnyHitFramesWithMoreTrianglesThanRaysOnSeveralWorkers) {
    const Frame frame = denseFrame();
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    const PassFrame pass(frame, primary.hits, occlusionPass(2, 0.8f));
    ASSERT_TRUE(tracesAsSubtrees(pass.geometry, {}, 2));
    EXPECT_FALSE(tracesAsSubtrees(pass.geometry, {}, 1)) << "one worker";
    FrameGeometry closest = pass.geometry;
    closest.query = HitQuery::Closest;
    EXPECT_FALSE(tracesAsSubtrees(closest, {}, 2)) << "closest hits";
    DacrtOptions mora, sampled, raySampling;
    mora.triangleFilter = TriangleFilter::Mora;
    sampled.split = SplitMethod::SampledMean;
    raySampling.splitCost = SplitCost::RaySampling;
    for (const DacrtOptions& options : {mora, sampled, raySampling}) EXPECT_FALSE(tracesAsSubtrees(pass.geometry, options, 2));
    const PassFrame many(frame, primary.hits, occlusionPass(64, 0.8f));
    ASSERT_GE(many.rays.rays.size(), many.geometry.triangles->size());
    EXPECT_FALSE(tracesAsSubtrees(many.geometry, {}, 2)) << "as many rays as triangles";
    ThreadPool pool(2);
    EXPECT_THROW(traceSubtrees(many.geometry, {}, pool), InternalError);
    EXPECT_THROW(traceSubtrees(pass.geometry, mora, pool), InternalError);
}

// A frame large enough for the cpu backend's threads (kSequentialBelowRays) with more triangles
// (an 82k-triangle sphere among the shapes) than its occlusion rays: traceCpu traces them as
// subtrees, on two workers, with the same hits as traceSubtrees and brute force's visibility
// (every 37th ray tested against every triangle; cpu-seq's for all of them).
TEST(Subtrees, TheCpuBackendTracesLargePassesOfFewerRaysAsSubtrees) {
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesAndDenseSphere(6), 128, 96, o);
    const TraceResult primary = frame.trace(Backend::CpuSeq);
    const PassFrame pass(frame, primary.hits, occlusionPass(4, 0.8f));
    const std::size_t rays = pass.rays.rays.size();
    ASSERT_GE(rays, kSequentialBelowRays);
    ASSERT_LT(rays, pass.geometry.triangles->size());
    const TraceResult cpu = pass.trace(Backend::Cpu, 0, 2);
    EXPECT_GT(subtreesMade(cpu), 1u);
    ThreadPool pool(2);
    EXPECT_TRUE(identicalHits(traceSubtrees(pass.geometry, {}, pool).hits, cpu.hits));
    EXPECT_TRUE(identicalVisibility(pass.trace(Backend::CpuSeq).hits, cpu.hits));
    EXPECT_TRUE(hitsAreTheirTrianglesOwn(pass, cpu.hits));
    std::size_t sampled = 0, differing = 0, hits = 0;
    for (std::size_t i = 0; i < rays; i += 37, ++sampled) {
        const Ray& ray = pass.rays.rays[i];
        Hit best = missHit(ray);
        for (std::uint32_t t = 0; t < pass.geometry.triangles->size() && best.prim == kMissPrim; ++t)
            testTriangle(ray, (*pass.geometry.triangles)[t], t, best);
        differing += (best.prim == kMissPrim) != (cpu.hits[i].prim == kMissPrim);
        hits += best.prim != kMissPrim;
    }
    EXPECT_EQ(differing, 0u) << "of " << sampled << " rays tested against every triangle";
    EXPECT_GT(hits, sampled / 20);
    EXPECT_LT(hits, sampled);
}

}  // namespace dacrt::test
