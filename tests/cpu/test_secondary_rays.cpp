// Secondary rays: the exact arithmetic they are made with, the origin offset, the sample
// sequence, and brute / cpu-seq / cpu agreeing on rays that start on surfaces.
#include <bit>
#include <algorithm>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"
#include "core/procedural.hpp"
#include "core/random.hpp"
#include "cpu/ray_grouping.hpp"
#include "cpu/secondary_rays.hpp"
#include "cpu/simd_kernels.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

// The integer versions the device runs (the host takes its own IEEE division and square root:
// these tests are why it may).
namespace device_math {
using namespace dacrt::shared;
using dacrt::shared::abs;  // glm has its own of each: these are the shaders'
using dacrt::shared::floatBitsToUint;
using dacrt::shared::max;
using dacrt::shared::uintBitsToFloat;
#undef DACRT_EXACT_MATH_GLSL
#define precise
#define DACRT_UNROLL
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-variable"
#include "exact_math.glsl"
#pragma GCC diagnostic pop
#undef DACRT_UNROLL
#undef precise
}  // namespace device_math

namespace {

// A float with a random significand and an exponent in [lo, hi], random sign.
float randomFloat(Random& random, int lo, int hi) {
    const int e = lo + int(random.index(std::size_t(hi - lo + 1)));
    const float m = 1.0f + float(random.uniform());
    const float v = std::ldexp(m, e);
    return random.uniform() < 0.5 ? -v : v;
}

bool sameBits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

}  // namespace

TEST(ExactMath, DivideRoundedIsIeeeDivision) {
    Random random(11);
    std::size_t checked = 0;
    for (int i = 0; i < 2000000; ++i) {
        const float a = randomFloat(random, -60, 60), b = randomFloat(random, -60, 60);
        ASSERT_TRUE(sameBits(device_math::divideRounded(a, b), a / b)) << a << " / " << b;
        ++checked;
    }
    // Quotients that need the round-to-even rule and the carry into the next power of two.
    for (float a : {1.0f, 3.0f, 0.1f, 1.9999999f, 16777215.0f, 0.0f, -0.0f})
        for (float b : {1.0f, 3.0f, 7.0f, 0.1f, 1.0000001f, -2.5f, 16777213.0f})
            EXPECT_TRUE(sameBits(device_math::divideRounded(a, b), a / b)) << a << " / " << b;
    EXPECT_EQ(checked, 2000000u);
}

TEST(ExactMath, SqrtRoundedIsIeeeSqrt) {
    Random random(12);
    for (int i = 0; i < 2000000; ++i) {
        const float x = std::abs(randomFloat(random, -120, 120));
        ASSERT_TRUE(sameBits(device_math::sqrtRounded(x), std::sqrt(x))) << x;
    }
    for (float x : {0.0f, 1.0f, 2.0f, 4.0f, 0.25f, 16777215.0f, 1.0000001f, 0.99999994f, 1e-30f, 3e30f})
        EXPECT_TRUE(sameBits(device_math::sqrtRounded(x), std::sqrt(x))) << x;
}

TEST(ExactMath, NormalizeRoundedGivesUnitVectorsAtEveryScale) {
    Random random(13);
    for (int i = 0; i < 100000; ++i) {
        const glm::vec3 v(randomFloat(random, -40, 40), randomFloat(random, -40, 40), randomFloat(random, -40, 40));
        const glm::vec3 n = device_math::normalizeRounded(v);
        ASSERT_EQ(n, shared::normalizeRounded(v));
        const glm::dvec3 exact = glm::normalize(glm::dvec3(v));
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(n[a], exact[a], 4e-7) << i;
    }
}

TEST(ExactMath, PcgHashIsTheRxsMXsStep) {
    // Reference values computed independently (Python, modulo 2^32).
    EXPECT_EQ(shared::pcgHash(0u), 129708002u);
    EXPECT_EQ(shared::pcgHash(1u), 2831084092u);
    EXPECT_EQ(shared::pcgHash(2u), 2055130248u);
    EXPECT_EQ(shared::pcgHash(123456789u), 4272394698u);
    EXPECT_EQ(shared::pcgHash(0xFFFFFFFFu), 3861530882u);
    EXPECT_EQ(shared::unitInterval(0xFFFFFFFFu), 1.0f - 0x1p-24f);
    EXPECT_EQ(shared::unitInterval(0xFFu), 0.0f);
}

TEST(SecondaryRays, SegmentRaysDivideAsTheHardwareDoes) {
    Random random(14);
    for (int i = 0; i < 100000; ++i) {
        const glm::vec3 d(randomFloat(random, -20, 20), randomFloat(random, -20, 20), randomFloat(random, -20, 20));
        const Ray r = shared::segmentRay(glm::vec3(1, 2, 3), d, 1.0f);
        for (int a = 0; a < 3; ++a) ASSERT_TRUE(sameBits(r.invDir[a], 1.0f / d[a]));
        const int kx = int(r.axes & 3u), ky = int((r.axes >> 2) & 3u), kz = int((r.axes >> 4) & 3u);
        ASSERT_TRUE(sameBits(r.shear.x, d[kx] / d[kz]) && sameBits(r.shear.y, d[ky] / d[kz]) &&
                    sameBits(r.shear.z, 1.0f / d[kz]));
        ASSERT_EQ(r.tmax, 1.0f);
    }
    // Components below 2^-64 are flushed, as makeRay flushes them.
    const Ray r = shared::segmentRay(glm::vec3(0), glm::vec3(1.0f, 1e-25f, -1e-30f), 2.0f);
    EXPECT_EQ(r.dir.y, 0.0f);
    EXPECT_EQ(r.dir.z, 0.0f);
    EXPECT_EQ(r.invDir.y, 0.0f);
}

// Rays leaving random points of random triangles, at scales from 1e-4 to 1e6 and offsets up
// to 1e6, into their hemisphere (grazing ones included): the origin lies on the normal's side
// of the triangle's plane, and the watertight test never finds the triangle itself.
TEST(SecondaryRays, OffsetOriginsNeverSeeTheirOwnTriangle) {
    Random random(15);
    std::size_t grazing = 0;
    std::uint32_t slot = 0;
    for (double scale : {1e-4, 1e-2, 1.0, 1e3, 1e6}) {
        for (double shift : {0.0, 1.0, 1e3, 1e6}) {
            for (int i = 0; i < 2000; ++i) {
                const glm::dvec3 centre = random.inBox(-1.0, 1.0) * shift;
                Triangle tri{};
                tri.v0 = glm::vec3(centre + random.inBox(-1.0, 1.0) * scale);
                tri.v1 = glm::vec3(centre + random.inBox(-1.0, 1.0) * scale);
                tri.v2 = glm::vec3(centre + random.inBox(-1.0, 1.0) * scale);
                if (shared::triangleHasNoArea(tri.v0, tri.v1, tri.v2)) continue;
                const float u = float(random.uniform()), v = float(random.uniform()) * (1.0f - u);
                const glm::dvec3 normal = glm::normalize(glm::cross(glm::dvec3(tri.v1 - tri.v0), glm::dvec3(tri.v2 - tri.v0)));
                // A primary ray from the front or from the back.
                const glm::vec3 incoming = glm::vec3(random.uniform() < 0.5 ? -normal : normal);
                const Ray primary = makeRay(glm::vec3(0), glm::dvec3(incoming));
                const shared::SurfaceSample s = shared::surfaceOfHit(primary, Hit{1.0f, 0u, u, v}, tri);
                ASSERT_TRUE(s.valid);
                const double side = glm::dot(glm::dvec3(s.origin) - glm::dvec3(tri.v0), glm::dvec3(s.normal));
                ASSERT_GT(side, 0.0) << "scale " << scale << " shift " << shift;
                for (int k = 0; k < 8; ++k) {
                    const Ray ray = shared::occlusionRay(s, slot++, 3u, kNoHitT).ray;
                    const double cosine = glm::dot(glm::normalize(glm::dvec3(ray.dir)), glm::dvec3(s.normal));
                    ASSERT_GT(cosine, 0.0);
                    grazing += cosine < 0.01;
                    const shared::TriangleHit h = shared::intersectWatertight(ray, tri.v0, tri.v1, tri.v2, false);
                    ASSERT_FALSE(h.hit && h.t > 0.0f) << "scale " << scale << " shift " << shift << " t " << h.t;
                }
            }
        }
    }
    EXPECT_GT(grazing, 0u) << "the sample should include grazing rays";
}

TEST(SecondaryRays, OcclusionRaysAreCosineDistributed) {
    const Triangle tri{{0, 0, 0}, 0u, {1, 0, 0}, 0.0f, {0, 1, 0}, 0.0f};
    const Ray primary = makeRay(glm::vec3(0.2f, 0.2f, 5.0f), glm::dvec3(0, 0, -1));
    const shared::SurfaceSample s = shared::surfaceOfHit(primary, Hit{5.0f, 0u, 0.2f, 0.2f}, tri);
    ASSERT_EQ(s.normal, glm::vec3(0, 0, 1));
    const int n = 40000;
    double cosine = 0.0, cosineSquared = 0.0;
    for (int i = 0; i < n; ++i) {
        const Ray r = shared::occlusionRay(s, std::uint32_t(i), 1u, 2.0f).ray;
        ASSERT_NEAR(glm::length(glm::dvec3(r.dir)), 1.0, 1e-6);
        ASSERT_EQ(r.tmax, 2.0f);
        cosine += r.dir.z;
        cosineSquared += double(r.dir.z) * r.dir.z;
    }
    // A cosine-weighted hemisphere: E[cos] = 2/3, E[cos^2] = 1/2.
    EXPECT_NEAR(cosine / n, 2.0 / 3.0, 0.005);
    EXPECT_NEAR(cosineSquared / n, 0.5, 0.005);
}

TEST(SecondaryRays, ShadowRaysOnlyWhereTheLightCanReach) {
    const Triangle tri{{-1, 0, -1}, 0u, {0, 0, 1}, 0.0f, {1, 0, -1}, 0.0f};  // the plane y = 0, normal +y
    const Ray primary = makeRay(glm::vec3(0, 3, 0), glm::dvec3(0, -1, 0));
    const shared::SurfaceSample s = shared::surfaceOfHit(primary, Hit{3.0f, 0u, 0.25f, 0.25f}, tri);
    ASSERT_GT(s.origin.y, 0.0f);
    ShadowLight light{};
    light.type = shared::kLightPoint;
    light.position = glm::vec3(0, 2, 0);
    shared::GeneratedRay g = shared::shadowRay(s, light);
    ASSERT_TRUE(g.traced);
    EXPECT_EQ(g.ray.tmax, 1.0f);
    light.position = glm::vec3(0, -2, 0);  // behind the surface: in shadow without a ray
    EXPECT_FALSE(shared::shadowRay(s, light).traced);
    light.position = glm::vec3(0, 2, 0);
    light.range = 1.5f;  // out of range
    EXPECT_FALSE(shared::shadowRay(s, light).traced);
    light.range = 0.0f;
    light.type = shared::kLightSpot;
    light.direction = glm::vec3(0, -1, 0);
    light.cosOuterSquared = 0.5f;  // 45 degrees
    EXPECT_TRUE(shared::shadowRay(s, light).traced);
    light.direction = glm::vec3(1, 0, 0);  // pointing sideways: outside the cone
    EXPECT_FALSE(shared::shadowRay(s, light).traced);
    light.type = shared::kLightDirectional;
    light.direction = glm::vec3(0, -1, 0);  // shining down onto the surface
    g = shared::shadowRay(s, light);
    ASSERT_TRUE(g.traced);
    EXPECT_EQ(g.ray.tmax, kNoHitT);
    EXPECT_EQ(g.ray.dir, glm::vec3(0, 1, 0));
}

namespace {

// Brute force against cpu-seq and cpu (regions and threads) on one pass.
void expectPassAgrees(const PassFrame& pass, bool closest) {
    const TraceResult reference = pass.trace(Backend::Brute, 0, 2);
    auto same = [&](const std::vector<Hit>& hits) {
        return closest ? identicalHits(reference.hits, hits) : identicalVisibility(reference.hits, hits);
    };
    EXPECT_TRUE(same(pass.trace(Backend::CpuSeq).hits)) << "cpu-seq";
    for (unsigned regions : {1u, 2u, 4u, 8u})
        for (unsigned threads : {1u, 2u})
            EXPECT_TRUE(same(pass.trace(Backend::Cpu, regions, threads).hits)) << "cpu, " << regions << " regions, "
                                                                               << threads << " threads";
    for (DivisionAxis axis : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z})
        EXPECT_TRUE(same(pass.trace(Backend::Cpu, 3, 2, axis).hits)) << "cpu along axis " << int(axis) - 1;
}

}  // namespace

// makeShadowRays is shadowRay lane by lane, on every SIMD target: random surfaces around
// point, spot and directional lights, some with a range, the light on or near their planes,
// at the range's and the cone's edges, and some surfaces nearly at the light (directions
// below 2^-64, or with components to flush); batches of every length up to the 256 a batch holds.
TEST(SecondaryRays, ShadowRaysInLanesAreShadowRayBitForBit) {
    for (const std::string& target : simd::availableTargets()) {
        SCOPED_TRACE("target " + target);
        simd::forceTarget(target);
        Random rng(43);
        std::size_t made = 0, refused = 0;
        for (int trial = 0; trial < 300; ++trial) {
            ShadowLight light{};
            const int type = trial % 3;
            light.type = type == 0 ? shared::kLightPoint : type == 1 ? shared::kLightSpot : shared::kLightDirectional;
            light.position = rng.vec3(-2.0f, 2.0f);
            light.direction = glm::vec3(glm::normalize(rng.onSphere()));
            light.range = rng.uniform() < 0.5 ? 0.0f : rng.uniformFloat(0.5f, 3.0f);
            light.cosOuterSquared = rng.uniformFloat(0.0f, 0.95f);
            ShadowBatch batch;
            batch.count = 1 + int(rng.index(ShadowBatch::kRays));
            std::vector<shared::SurfaceSample> surfaces(std::size_t(batch.count));
            for (int j = 0; j < batch.count; ++j) {
                shared::SurfaceSample& s = surfaces[std::size_t(j)];
                s.normal = glm::vec3(glm::normalize(rng.onSphere()));
                const double pick = rng.uniform();
                if (pick < 0.1) {  // at the light, or a hair from it
                    s.point = light.position;
                    s.origin = light.position + glm::vec3(rng.onSphere()) * (rng.uniform() < 0.5 ? 0x1p-70f : 0x1p-40f);
                } else {
                    s.point = light.position + glm::vec3(rng.onSphere()) * rng.uniformFloat(0.1f, 4.0f);
                    if (pick < 0.3) s.point[rng.index(3)] = light.position[rng.index(3)];  // components to flush
                    s.origin = s.point + s.normal * 1e-4f;
                }
                if (rng.uniform() < 0.1) s.normal = glm::normalize(light.position - s.point + glm::vec3(0.0f, 0.0f, 1e-3f));
                s.valid = true;
                for (int c = 0; c < 3; ++c) {
                    batch.point[c][j] = s.point[c];
                    batch.normal[c][j] = s.normal[c];
                    batch.origin[c][j] = s.origin[c];
                }
            }
            std::vector<Ray> rays(std::size_t(batch.count));
            std::vector<std::uint32_t> which(std::size_t(batch.count));
            const int count = makeShadowRays(batch, light, rays.data(), which.data());
            int k = 0;
            for (int j = 0; j < batch.count; ++j) {
                const shared::GeneratedRay g = shared::shadowRay(surfaces[std::size_t(j)], light);
                if (!g.traced) {
                    ++refused;
                    continue;
                }
                ASSERT_LT(k, count) << "trial " << trial << " surface " << j;
                ASSERT_EQ(which[std::size_t(k)], std::uint32_t(j)) << "trial " << trial;
                ASSERT_EQ(std::memcmp(&rays[std::size_t(k)], &g.ray, sizeof(Ray)), 0) << "trial " << trial << " surface " << j;
                ++k;
                ++made;
            }
            ASSERT_EQ(k, count) << "trial " << trial;
        }
        EXPECT_GT(made, 10000u);
        EXPECT_GT(refused, 5000u);
    }
    simd::forceTarget("");
}

TEST(BackendsAgree, OcclusionRaysClosestAndAnyHit) {
    // Rays from every visible surface in every direction of its hemisphere: no common near
    // side, so every split classifies them (ChildOrder::PerRay).
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesScene(), 48, 36, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    for (float length : {0.8f, kNoHitT}) {
        SCOPED_TRACE("length " + std::to_string(length));
        for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
            const PassFrame pass(frame, primary.hits, occlusionPass(4, length), query);
            ASSERT_EQ(pass.geometry.order, ChildOrder::PerRay);
            ASSERT_GT(pass.rays.rays.size(), 3000u);
            ASSERT_GT(hitCount(pass.trace(Backend::Brute, 0, 2).hits), pass.rays.rays.size() / 20);
            expectPassAgrees(pass, query == HitQuery::Closest);
        }
    }
}

TEST(BackendsAgree, AnyHitRaysOfDifferentLengthsAreTracedWithTheirOwn) {
    // A pass's rays share their segment, and the ray filter then broadcasts the first one's
    // (simd::SharedRayFields::Segment). Where one ray in three is shortened after the frame is
    // made, that is found when the trace starts, and each ray's own segment is read.
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesScene(), 48, 36, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    PassFrame pass(frame, primary.hits, occlusionPass(4, 0.8f), HitQuery::Any);
    ASSERT_TRUE(raysShareSegment(pass.rays.rays));
    const std::size_t before = hitCount(pass.trace(Backend::Brute, 0, 2).hits);
    for (std::size_t i = 0; i < pass.rays.rays.size(); i += 3) pass.rays.rays[i].tmax = 0.1f;
    ASSERT_FALSE(raysShareSegment(pass.rays.rays));
    const std::size_t after = hitCount(pass.trace(Backend::Brute, 0, 2).hits);
    ASSERT_LT(after, before);  // the shortened rays are read: fewer of them reach a triangle
    ASSERT_GT(after, 0u);
    expectPassAgrees(pass, false);
}

TEST(BackendsAgree, ShadowRaysTowardsPointAndDirectionalLights) {
    CameraOptions o;
    o.eye = glm::dvec3(-1.0, 2.0, 4.0);
    const Frame frame(shapesScene(), 48, 36, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    const SecondaryPass directional = directionalShadowPass({0.4, -1.0, -0.3});
    for (const SecondaryPass& p : {pointShadowPass({0.3f, 1.6f, 0.4f}), pointShadowPass({0.0f, -0.2f, 0.0f}), directional}) {
        for (HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
            const PassFrame pass(frame, primary.hits, p, query);
            ASSERT_GT(pass.rays.rays.size(), 500u);
            if (p.light.type == shared::kLightDirectional) {
                EXPECT_EQ(pass.geometry.order, ChildOrder::NearSide);
            }
            expectPassAgrees(pass, query == HitQuery::Closest);
        }
    }
}

TEST(SecondaryRays, ABatchOfSamplesMakesTheRaysTheWholePassWould) {
    // The gpu splits an occlusion pass its device buffers cannot hold into batches of samples
    // (cmd/frame_passes.cpp): each batch must draw the same random streams as the whole pass.
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesScene(), 24, 18, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    ThreadPool pool(2);
    const SecondaryPass whole = occlusionPass(7, 0.8f);
    const SecondaryRays all = makeSecondaryRays(whole, frame.rays, primary.hits, frame.scene.triangles, pool);
    std::size_t compared = 0;
    for (std::uint32_t first : {0u, 3u, 6u}) {
        SecondaryPass batch = whole;
        batch.firstSample = first;
        batch.raysPerHit = std::min(3u, 7u - first);
        batch.samplesPerHit = 7;
        const SecondaryRays part = makeSecondaryRays(batch, frame.rays, primary.hits, frame.scene.triangles, pool);
        ASSERT_EQ(part.slotCount, frame.rays.size() * batch.raysPerHit);
        for (std::size_t r = 0; r < part.rays.size(); ++r) {
            const std::uint32_t pixel = part.slots[r] / batch.raysPerHit, sample = first + part.slots[r] % batch.raysPerHit;
            const auto at = std::lower_bound(all.slots.begin(), all.slots.end(), pixel * 7 + sample);
            ASSERT_TRUE(at != all.slots.end() && *at == pixel * 7 + sample);
            ASSERT_EQ(std::memcmp(&all.rays[std::size_t(at - all.slots.begin())], &part.rays[r], sizeof(Ray)), 0);
            ++compared;
        }
    }
    EXPECT_EQ(compared, all.rays.size());
}

TEST(SecondaryRays, MadeInChunksAreEveryRayOfTheDefinitionInSlotOrder) {
    // makeSecondaryRays makes the rays in chunks of 1,024 primary rays, each into room for its
    // own hits: the result must be secondaryRaysOf's rays, primary ray by primary ray, whatever
    // the chunks hit (here the scene fills part of the view, so some chunks hit nothing and
    // the shadow pass leaves out the surfaces the light cannot reach).
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesScene(), 96, 72, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    std::size_t missing = 0;
    for (const Hit& h : primary.hits) missing += h.prim == kMissPrim;
    ASSERT_GT(missing, frame.rays.size() / 10);
    ASSERT_LT(missing, frame.rays.size() - frame.rays.size() / 10);
    ThreadPool pool(2);
    // Occlusion and shadow rays are made in batches of 256 several at a time
    // (occlusion_ray_rows.hpp), on every SIMD target: 300 samples a hit span batches; the
    // lights are a point light, a directional one and a spot light with a range.
    SecondaryPass spot = pointShadowPass({0.3f, 1.6f, 0.4f});
    spot.light.type = shared::kLightSpot;
    spot.light.direction = glm::vec3(glm::normalize(glm::dvec3(-0.1, -1.0, -0.2)));
    spot.light.cosOuterSquared = 0.3f;
    spot.light.range = 2.4f;
    for (const std::string& target : simd::availableTargets())
    for (const SecondaryPass& pass : {occlusionPass(3, 0.8f), occlusionPass(300, kNoHitT, 12345),
                                      pointShadowPass({0.3f, 1.6f, 0.4f}), directionalShadowPass({0.2, -1.0, -0.4}),
                                      spot}) {
        SCOPED_TRACE("target " + target);
        simd::forceTarget(target);
        std::vector<Ray> rays;
        std::vector<std::uint32_t> slots;
        for (std::uint32_t i = 0; i < frame.rays.size(); ++i)
            secondaryRaysOf(pass, i, primary.hits[i], [&]() -> const Ray& { return frame.rays[i]; },
                            frame.scene.triangles, [&](std::uint32_t slot, const Ray& ray) {
                                rays.push_back(ray);
                                slots.push_back(slot);
                            });
        const SecondaryRays made = makeSecondaryRays(pass, frame.rays, primary.hits, frame.scene.triangles, pool);
        EXPECT_EQ(made.slotCount, std::uint64_t(frame.rays.size()) * pass.raysPerHit) << pass.name;
        ASSERT_GT(rays.size(), 1000u) << pass.name;
        ASSERT_EQ(made.slots, slots) << pass.name;
        ASSERT_EQ(made.rays.size(), rays.size()) << pass.name;
        EXPECT_EQ(std::memcmp(made.rays.data(), rays.data(), rays.size() * sizeof(Ray)), 0) << pass.name;
    }
    simd::forceTarget("");
}

TEST(SecondaryRays, GroupingByOctantIsAStablePermutationThatHitsPerSlotUndoes) {
    CameraOptions o;
    o.eye = glm::dvec3(0.5, 1.5, 4.0);
    const Frame frame(shapesScene(), 48, 36, o);
    const TraceResult primary = frame.trace(Backend::Brute, 0, 2);
    const PassFrame pass(frame, primary.hits, occlusionPass(4, 0.8f));
    const SecondaryRays& made = pass.rays;
    ASSERT_GT(made.rays.size(), 3000u);
    ThreadPool pool(2);
    GroupingBuffers buffers;
    for (int run = 0; run < 2; ++run) {  // the second run reuses the buffers the first kept
        SecondaryRays grouped = made;
        const OctantStarts starts = groupByOctant(grouped, buffers, pool);
        ASSERT_EQ(grouped.slotCount, made.slotCount);
        ASSERT_EQ(grouped.rays.size(), made.rays.size());
        ASSERT_EQ(grouped.slots.size(), made.slots.size());
        EXPECT_EQ(starts.front(), 0u);
        EXPECT_EQ(starts.back(), made.rays.size());
        // Where each slot's ray was made.
        std::vector<std::size_t> madeAt(made.slotCount, made.rays.size());
        for (std::size_t i = 0; i < made.slots.size(); ++i) madeAt[made.slots[i]] = i;
        std::vector<bool> seen(made.slotCount, false);
        unsigned octantsUsed = 0;
        for (unsigned octant = 0; octant < kOctants; ++octant) {
            octantsUsed += starts[octant] < starts[octant + 1];
            for (std::size_t i = starts[octant]; i < starts[octant + 1]; ++i) {
                const std::uint32_t slot = grouped.slots[i];
                ASSERT_LT(madeAt[slot], made.rays.size()) << "slot " << slot << " had no ray";
                ASSERT_FALSE(seen[slot]) << "slot " << slot << " twice";
                seen[slot] = true;
                EXPECT_EQ(std::memcmp(&grouped.rays[i], &made.rays[madeAt[slot]], sizeof(Ray)), 0) << i;
                EXPECT_EQ(directionOctant(grouped.rays[i]), octant) << i;
                if (i > starts[octant]) {
                    EXPECT_LT(grouped.slots[i - 1], slot) << "order within octant " << octant;
                }
            }
        }
        EXPECT_EQ(octantsUsed, kOctants);  // a hemisphere around every normal: every sign mix
        // A hit naming its slot lands in that slot, as the slot order's own would.
        auto slotHits = [](const SecondaryRays& r) {
            std::vector<Hit> hits(r.slots.size());
            for (std::size_t i = 0; i < hits.size(); ++i) hits[i] = Hit{float(r.slots[i]), r.slots[i], 0.0f, 0.0f};
            return hits;
        };
        const std::vector<Hit> scattered = hitsPerSlot(grouped, slotHits(grouped));
        EXPECT_TRUE(identicalHits(hitsPerSlot(made, slotHits(made)), scattered));
        for (std::size_t s = 0; s < scattered.size(); ++s)
            EXPECT_EQ(scattered[s].prim, madeAt[s] < made.rays.size() ? std::uint32_t(s) : kNotTracedPrim) << s;
    }
}

// hitsPerSlot gives each ray's hit in its slot and kNotTracedPrim in every other slot, from the
// first slot to the last, with no ray, with rays in slot order and out of it; on the calling
// thread and on a pool of 2, with slot counts of several fill chunks and rays of several scan
// chunks.
TEST(SecondaryRays, PassesTakeTheirTriangleLimitWhereNoneWasAskedFor) {
    DacrtOptions options;
    EXPECT_EQ(passDacrtOptions(options).triLimit, kCpuSimdSecondaryTriangleLimit);
    EXPECT_EQ(passDacrtOptions(options).resolvedFor(Backend::Cpu).triLimit, kCpuSimdSecondaryTriangleLimit);
    EXPECT_EQ(passDacrtOptions(options).rayLimit, 0u);  // the backend's default
    options.triLimit = 20;  // asked for: kept
    EXPECT_EQ(passDacrtOptions(options).triLimit, 20u);
    options.triLimit = 0;
    options.intersector = Intersector::MollerTrumbore;  // not the SIMD leaf: its own default
    EXPECT_EQ(passDacrtOptions(options).resolvedFor(Backend::CpuSeq).triLimit, kCpuLeafLimit);
}

TEST(SecondaryRays, HitsPerSlotPutsEveryHitInItsSlotInOrderOrNot) {
    auto slotsWith = [](std::vector<std::uint32_t> slots, std::uint64_t slotCount) {
        SecondaryRays r;
        r.slots = std::move(slots);
        r.rays.resize(r.slots.size());
        r.slotCount = slotCount;
        return r;
    };
    auto hitsOf = [](const SecondaryRays& r) {
        std::vector<Hit> hits;
        for (std::uint32_t slot : r.slots) hits.push_back(Hit{0.5f * float(slot), slot + 1000u, 0.25f, 0.125f});
        return hits;
    };
    struct Case {
        std::vector<std::uint32_t> slots;
        std::uint32_t slotCount;
    };
    std::vector<Case> cases;
    for (std::vector<std::uint32_t> slots : std::vector<std::vector<std::uint32_t>>{
             {}, {0}, {6}, {0, 1, 2, 3, 4, 5, 6}, {1, 3, 4, 6}, {2, 5, 1, 6}, {0, 4, 3}, {6, 5, 4, 3, 2, 1, 0}})
        cases.push_back({std::move(slots), 7});
    const std::uint32_t many = 3 * std::uint32_t(kFillChunk) + 5;  // a ray in every third slot
    std::vector<std::uint32_t> everyThird;
    for (std::uint32_t s = 1; s < many; s += 3) everyThird.push_back(s);
    cases.push_back({everyThird, many});
    std::reverse(everyThird.begin(), everyThird.end());
    cases.push_back({everyThird, many});
    ThreadPool pool(2);
    for (ThreadPool* on : {static_cast<ThreadPool*>(nullptr), &pool})
        for (const Case& c : cases) {
            const SecondaryRays rays = slotsWith(c.slots, c.slotCount);
            const std::vector<Hit> perSlot = hitsPerSlot(rays, hitsOf(rays), on);
            ASSERT_EQ(perSlot.size(), c.slotCount);
            std::vector<std::uint8_t> traced(c.slotCount, 0);
            for (std::uint32_t s : c.slots) traced[s] = 1;
            for (std::uint32_t s = 0; s < c.slotCount; ++s) {
                ASSERT_EQ(perSlot[s].prim, traced[s] ? s + 1000u : kNotTracedPrim)
                    << "slot " << s << " of case " << c.slots.size() << (on ? " on a pool" : "");
                ASSERT_EQ(perSlot[s].t, traced[s] ? 0.5f * float(s) : 0.0f) << "slot " << s;
                ASSERT_EQ(perSlot[s].u, traced[s] ? 0.25f : 0.0f) << "slot " << s;
                ASSERT_EQ(perSlot[s].v, traced[s] ? 0.125f : 0.0f) << "slot " << s;
            }
        }
    // A slot past the pass's slots is refused, on the calling thread and on the pool, and a
    // slot list that does not match the rays.
    for (ThreadPool* on : {static_cast<ThreadPool*>(nullptr), &pool}) {
        const SecondaryRays past = slotsWith({1, 7}, 7);
        EXPECT_THROW(hitsPerSlot(past, hitsOf(past), on), InternalError);
    }
    SecondaryRays unnamed = slotsWith({1, 2}, 7);
    unnamed.slots.pop_back();
    EXPECT_THROW(hitsPerSlot(unnamed, std::vector<Hit>(2), nullptr), InternalError);
}

TEST(SecondaryRays, BatchesAreEqualRunsOfAtMostTheLimit) {
    EXPECT_EQ(rayBatches(10, 4), (std::vector<std::size_t>{0, 3, 6, 10}));
    EXPECT_EQ(rayBatches(8, 4), (std::vector<std::size_t>{0, 4, 8}));
    EXPECT_EQ(rayBatches(3, 4), (std::vector<std::size_t>{0, 3}));
    EXPECT_EQ(rayBatches(0, 4), (std::vector<std::size_t>{0, 0}));
    const std::vector<std::size_t> room = rayBatches(1228800, kPassBatchRays);
    EXPECT_EQ(room.size(), 20u);  // 19 batches of 64,673 or 64,674 rays
    for (std::size_t b = 0; b + 1 < room.size(); ++b) EXPECT_LE(room[b + 1] - room[b], kPassBatchRays);
    // Side by side on k workers: the fewest batches that k divides.
    EXPECT_EQ(rayBatches(10, 4, 2), (std::vector<std::size_t>{0, 2, 5, 7, 10}));
    EXPECT_EQ(rayBatches(3, 4, 2), (std::vector<std::size_t>{0, 1, 3}));
    EXPECT_EQ(rayBatches(8, 4, 2), (std::vector<std::size_t>{0, 4, 8}));
    EXPECT_EQ(rayBatches(0, 4, 2), (std::vector<std::size_t>{0, 0, 0}));
    EXPECT_EQ(rayBatches(1228800, kPassBatchRays, 2).size(), 21u);
    EXPECT_EQ(rayBatches(1228800, kPassBatchRays, 0), room);  // 0 reads as 1
}
