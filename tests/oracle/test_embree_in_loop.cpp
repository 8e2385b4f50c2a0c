// Embree with its rays made in the tracing loop (peers/embree_in_loop.hpp), as the bench's
// default embree rows run it, against Embree on the same rays made and stored first (the
// bench's "stored rays" rows): the same primary hits bit for bit (primitive, t, u, v) and the
// same answer in every slot of every shadow and occlusion pass, on a small procedural scene
// with single-sided faces seen from behind and on the Bunny.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/gltf_loader.hpp"
#include "peers/embree_in_loop.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

bool bitIdentical(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

// Every field of every hit, bit for bit; reports the first few that differ.
::testing::AssertionResult identicalAnswers(const std::vector<Hit>& stored, const std::vector<Hit>& inLoop) {
    if (stored.size() != inLoop.size())
        return ::testing::AssertionFailure() << "sizes " << stored.size() << " and " << inLoop.size();
    std::size_t differing = 0;
    std::string examples;
    for (std::size_t i = 0; i < stored.size(); ++i) {
        if (bitIdentical(stored[i], inLoop[i])) continue;
        if (++differing <= 5)
            examples += " [" + std::to_string(i) + ": stored prim " + std::to_string(stored[i].prim) + " t " +
                        std::to_string(stored[i].t) + ", in the loop prim " + std::to_string(inLoop[i].prim) + " t " +
                        std::to_string(inLoop[i].t) + "]";
    }
    if (differing == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << differing << " of " << stored.size() << " differ:" << examples;
}

std::size_t countPrim(const std::vector<Hit>& hits, std::uint32_t prim) {
    std::size_t n = 0;
    for (const Hit& h : hits) n += h.prim == prim;
    return n;
}

// The frame and its passes both ways, on each build mode (robust, the bench's default).
void expectInLoopAnswersAsStored(const Scene& scene, const Camera& camera, int width, int height,
                                 const std::vector<SecondaryPass>& passes, const std::string& name) {
    ThreadPool pool(2);
    const std::vector<Ray> rays = primaryRays(camera, width, height);
    const PixelRays pixels(camera, width, height);
    for (EmbreeBuild build : {EmbreeBuild::Dynamic, EmbreeBuild::Refit, EmbreeBuild::Static}) {
        const std::string what = name + ", " + toString(build);
        EmbreeOptions options;
        options.build = build;
        options.imageWidth = std::uint32_t(width);
        const EmbreeScene embree(scene.triangles, options);
        const TraceResult stored = embree.trace(rays, pool);
        std::vector<Hit> inLoop;
        traceCameraInLoop(embree, pixels, pool, inLoop);
        EXPECT_TRUE(identicalAnswers(stored.hits, inLoop)) << what << ", primary";
        EXPECT_GT(hitCount(inLoop), rays.size() / 10) << what << ": the view should show the scene";
        EXPECT_GT(countPrim(inLoop, kMissPrim), 0u) << what << ": and some background";
        for (const SecondaryPass& pass : passes) {
            const SecondaryRays made = makeSecondaryRays(pass, rays, stored.hits, scene.triangles, pool);
            const std::vector<Hit> storedSlots = hitsPerSlot(made, embree.trace(made.rays, pool, HitQuery::Any).hits);
            std::vector<Hit> slots = {Hit{1.0f, 7u, 0.5f, 0.5f}};  // memory from an earlier frame, overwritten
            const std::uint64_t raysMade = occludeSecondaryInLoop(embree, pass, pixels, inLoop, scene.triangles, pool, slots);
            const std::string passName = what + ", " + pass.name;
            EXPECT_EQ(raysMade, made.rays.size()) << passName;
            EXPECT_TRUE(identicalAnswers(storedSlots, slots)) << passName;
            // Each kind of answer occurs, so that a tracer answering one way everywhere fails.
            EXPECT_GT(countPrim(slots, kUnnamedHitPrim), 0u) << passName << ": occluded slots";
            EXPECT_GT(countPrim(slots, kMissPrim), 0u) << passName << ": clear slots";
            EXPECT_GT(countPrim(slots, kNotTracedPrim), 0u) << passName << ": slots without a ray";
        }
    }
}

SecondaryPass named(SecondaryPass pass, const std::string& name) {
    pass.name = name;
    return pass;
}

}  // namespace

// PixelRays, which the in-loop tracer makes its camera rays with, gives primaryRays' rays bit
// for bit, one at a time and four in a row (a tile's row; none made SIMD for an orthographic
// camera, whose rays are then made one at a time).
TEST(PixelRays, ArePrimaryRaysPixelByPixel) {
    const Scene s = shapesScene();
    CameraOptions raised;
    raised.eye = glm::dvec3(0.5, 1.5, 4.0);
    for (const Camera& camera : {defaultCamera(s, 37, 29, raised), orthographicView({1.0, 2.0, 5.0}, 2.5)}) {
        const bool orthographic = camera.projection == Projection::Orthographic;
        const std::vector<Ray> rays = primaryRays(camera, 37, 29, {0.25, 0.75});
        const PixelRays pixels(camera, 37, 29, {0.25, 0.75});
        std::size_t differing = 0;
        for (int y = 0; y < 29; ++y)
            for (int x = 0; x < 37; ++x) {
                const Ray made = pixels.ray(x, y);
                differing += std::memcmp(&made, &rays[std::size_t(y) * 37 + std::size_t(x)], sizeof(Ray)) != 0;
            }
        for (int y = 0; y < 29; ++y)
            for (int x0 = 0; x0 < 37; x0 += 4) {
                Ray span[4];
                const int made = pixels.rowRays(y, x0, 4, span);
                EXPECT_EQ(made, orthographic ? 0 : 4);
                for (int x = x0; x < std::min(x0 + made, 37); ++x)
                    differing += std::memcmp(&span[x - x0], &rays[std::size_t(y) * 37 + std::size_t(x)], sizeof(Ray)) != 0;
            }
        EXPECT_EQ(differing, 0u) << (orthographic ? "orthographic" : "perspective");
    }
}

// The shapes under a single-sided ceiling seen from below (the face filter decides every
// shadow ray towards the light above it), at an odd size (partial tiles and runs).
TEST(EmbreeInLoop, AnswersAsOnStoredRaysOnShapesUnderACeiling) {
    std::vector<Mesh> meshes = shapesMeshes();
    meshes.push_back(grid({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 4, 4));
    const Scene scene = sceneFromMeshes(meshes, "shapes under a ceiling");
    CameraOptions view;
    view.eye = glm::dvec3(0.5, 0.6, 4.0);
    const std::vector<SecondaryPass> passes = {
        named(pointShadowPass({0.3f, 2.0f, 0.4f}), "shadow, light above the ceiling"),
        named(pointShadowPass({0.0f, -0.2f, 0.0f}), "shadow, light among the shapes"),
        named(directionalShadowPass({0.3, -1.0, -0.4}), "shadow, directional"),
        named(occlusionPass(4, 0.8f), "occlusion 0.8"),
        named(occlusionPass(3, kNoHitT), "occlusion unbounded")};
    expectInLoopAnswersAsStored(scene, defaultCamera(scene, 61, 45, view), 61, 45, passes, "shapes under a ceiling");
}

// The Bunny at the bench's size, lit by a directional light, with four occlusion rays per hit.
TEST(EmbreeInLoop, AnswersAsOnStoredRaysOnTheBunny) {
    DACRT_REQUIRE_SHARED_SCENE(path, "bunny.glb");
    const Scene bunny = loadGltf(path);
    const Box box = sceneBounds(bunny.triangles);
    const float diagonal = glm::length(box.extent());
    const std::vector<SecondaryPass> passes = {named(directionalShadowPass({0.4, -1.0, -0.6}), "shadow, directional"),
                                               named(occlusionPass(4, 0.1f * diagonal), "occlusion")};
    expectInLoopAnswersAsStored(bunny, defaultCamera(bunny, 640, 480), 640, 480, passes, "bunny");
}
