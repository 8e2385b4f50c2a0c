#pragma once
// Secondary passes made on the host: shadow and occlusion rays from the primary hits, by
// shaders/secondary_rays.glsl compiled as C++ (the gpu backend runs the same file on the
// device, so both make the same rays bit for bit), and the pass's results slot by slot.
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/occlusion_ray_rows.hpp"
#include "cpu/options.hpp"
#include "cpu/predicates.hpp"
#include "cpu/simd_kernels.hpp"

namespace dacrt::shared {
inline uint floatBitsToUint(float x) { return std::bit_cast<uint>(x); }
inline float uintBitsToFloat(uint x) { return std::bit_cast<float>(x); }
inline float sqrt(float x) { return std::sqrt(x); }
#define precise
#define IN(T) const T&
#define DACRT_UNROLL
#define DACRT_HOST_IEEE_ARITHMETIC
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
namespace {  // GLSL has no `inline`: internal linkage keeps one copy per translation unit legal
#include "secondary_rays.glsl"
}
#pragma GCC diagnostic pop
#undef DACRT_HOST_IEEE_ARITHMETIC
#undef DACRT_UNROLL
#undef IN
#undef precise
}  // namespace dacrt::shared

namespace dacrt {

using shared::ShadowLight;

// One secondary pass of a frame: what it makes from each primary hit.
struct SecondaryPass {
    std::string name;                        // "shadow (key light)", "occlusion"
    std::uint32_t kind = shared::kPassShadow;  // shared::kPassShadow or kPassOcclusion
    ShadowLight light{};                     // kPassShadow
    std::uint32_t raysPerHit = 1;            // kPassOcclusion: samples per hit in this pass...
    std::uint32_t firstSample = 0;           // ... [firstSample, + raysPerHit) of samplesPerHit
    std::uint32_t samplesPerHit = 0;         // 0: raysPerHit (the pass holds every sample)
    float occlusionDistance = 0.0f;          // kPassOcclusion: the rays' length
    std::uint32_t sampleSeed = 0;            // kPassOcclusion: the sample sequence
};

// The light as the shadow pass traces it, in float32.
ShadowLight shadowLightOf(const Light& light);

// Sample k of primary ray i draws occlusion stream i * samplesPerHit + firstSample + k, so
// that a pass split into batches of samples makes the rays the whole pass would.
std::uint32_t occlusionStream(const SecondaryPass& pass, std::uint32_t primary, std::uint32_t k);

// Whether a primary ray's hit is a surface that may send secondary rays (not a miss, and traced).
inline bool hitSendsRays(const Hit& hit) { return hit.prim != kMissPrim && hit.prim != kNotTracedPrim; }

// How many of the primary hits send rays (hitSendsRays).
inline std::uint64_t surfacesSendingRays(const std::vector<Hit>& primaryHits) {
    std::uint64_t surfaces = 0;
    for (const Hit& h : primaryHits) surfaces += hitSendsRays(h);
    return surfaces;
}

// The rays primary ray i sends in the pass, in slot order: emit(slot, ray) for each one made
// (slot i * raysPerHit + k): none from a miss, a shadow ray only where the light can reach the
// surface, the occlusion samples. primaryRay() returns ray i (a Ray), asked for only where it
// hit: a tracer that makes rays in its loop (peers/embree_in_loop.hpp) makes it only there.
template <typename PrimaryRay, typename Emit>
void secondaryRaysOf(const SecondaryPass& pass, std::uint32_t i, const Hit& hit, PrimaryRay&& primaryRay,
                     const std::vector<Triangle>& triangles, Emit&& emit) {
    if (!hitSendsRays(hit)) return;
    const shared::SurfaceSample surface = shared::surfaceOfHit(primaryRay(), hit, triangles[hit.prim]);
    for (std::uint32_t k = 0; k < pass.raysPerHit; ++k) {
        const shared::GeneratedRay g =
            pass.kind == shared::kPassShadow
                ? shared::shadowRay(surface, pass.light)
                : shared::occlusionRay(surface, occlusionStream(pass, i, k), pass.sampleSeed, pass.occlusionDistance);
        if (g.traced) emit(i * pass.raysPerHit + k, g.ray);
    }
}

// The rays primary rays first .. end - 1 send in the pass, in slot order, as secondaryRaysOf
// makes them one primary ray at a time (the same rays, emitted in the same order), made in
// batches several at a time (occlusion_ray_rows.hpp). primaryRayOf(i) returns ray i, asked for
// only where it hit.
template <typename PrimaryRayOf, typename Emit>
void secondaryRaysOfRange(const SecondaryPass& pass, std::size_t first, std::size_t end, const Hit* hits,
                          PrimaryRayOf&& primaryRayOf, const std::vector<Triangle>& triangles, Emit&& emit) {
    // onSurface(i, surface) for each primary ray whose hit has a surface that sends rays, in
    // order; the hit triangles lie anywhere in the scene's array: each asked for a few hits ahead.
    constexpr std::size_t kHitsAhead = 8;
    const auto forEachSurface = [&](auto&& onSurface) {
        for (std::size_t i = first; i < end; ++i) {
            if (i + kHitsAhead < end && hitSendsRays(hits[i + kHitsAhead]))
                simd::prefetchTriangle(triangles[hits[i + kHitsAhead].prim]);
            if (!hitSendsRays(hits[i])) continue;
            const shared::SurfaceSample s = shared::surfaceOfHit(primaryRayOf(i), hits[i], triangles[hits[i].prim]);
            if (s.valid) onSurface(std::uint32_t(i), s);  // else shadowRay and occlusionRay make none
        }
    };
    if (pass.kind == shared::kPassShadow) {
        // A shadow ray per surface, each emitted raysPerHit times as secondaryRaysOf emits it.
        ShadowBatch batch;
        std::uint32_t firstSlot[ShadowBatch::kRays], surface[ShadowBatch::kRays];
        Ray rays[ShadowBatch::kRays];
        const auto flush = [&] {
            const int made = makeShadowRays(batch, pass.light, rays, surface);
            for (int r = 0; r < made; ++r)
                for (std::uint32_t k = 0; k < pass.raysPerHit; ++k) emit(firstSlot[surface[r]] + k, rays[r]);
            batch.count = 0;
        };
        forEachSurface([&](std::uint32_t i, const shared::SurfaceSample& s) {
            if (batch.count == ShadowBatch::kRays) flush();
            const int j = batch.count++;
            for (int c = 0; c < 3; ++c) {
                batch.point[c][j] = s.point[c];
                batch.normal[c][j] = s.normal[c];
                batch.origin[c][j] = s.origin[c];
            }
            firstSlot[j] = i * pass.raysPerHit;
        });
        if (batch.count > 0) flush();
        return;
    }
    OcclusionBatch batch;
    std::uint32_t slots[OcclusionBatch::kRays];
    Ray rays[OcclusionBatch::kRays];
    const auto flush = [&] {
        makeOcclusionRays(batch, pass.sampleSeed, pass.occlusionDistance, rays);
        for (int j = 0; j < batch.count; ++j) emit(slots[j], rays[j]);
        batch.count = 0;
    };
    forEachSurface([&](std::uint32_t i, const shared::SurfaceSample& s) {
        for (std::uint32_t k = 0; k < pass.raysPerHit; ++k) {
            if (batch.count == OcclusionBatch::kRays) flush();
            const int j = batch.count++;
            batch.stream[j] = occlusionStream(pass, i, k);
            for (int c = 0; c < 3; ++c) {
                batch.normal[c][j] = s.normal[c];
                batch.origin[c][j] = s.origin[c];
            }
            slots[j] = i * pass.raysPerHit + k;
        }
    });
    if (batch.count > 0) flush();
}

// The rays of a pass: one slot per primary ray and sample (slot = primary index * raysPerHit
// + sample); slots without a ray (a miss, a surface the light cannot reach) are left out.
struct SecondaryRays {
    std::vector<Ray> rays;                 // the rays made, in slot order
    std::vector<std::uint32_t> slots;      // rays[i] fills slots[i]
    std::uint64_t slotCount = 0;
};

// The DACRT options the cpu backends trace a pass alone with: its rays start on the surfaces
// in a cell (so that a split divides them with its triangles), hence the triangle limit
// kCpuSimdSecondaryTriangleLimit where none was asked for and the default tests run (the
// others keep their own default, kCpuLeafLimit). Passes traced together (the Dragon's: fewer
// rays than triangles, as subtrees) keep the backend's default, measured faster there.
DacrtOptions passDacrtOptions(const DacrtOptions& options);

// Where every ray of the pass ends (each starts at shared::kSegmentStart).
float passSegmentEnd(const SecondaryPass& pass);

// Largest slot count of a pass (slots are 32-bit on the device, kNotTracedPrim reserved).
constexpr std::uint64_t kMaxSecondarySlots = 0xFFFFFFF0ull;
// Throws InputError when the pass has more slots than kMaxSecondarySlots.
std::uint64_t secondarySlots(const SecondaryPass& pass, std::uint64_t primaryRays);

// The primary rays in chunks, and how many rays each chunk makes in a pass at most
// (raysPerHit for each hit that sends rays: hitSendsRays), counted in chunks side by side.
struct PassRayCounts {
    std::size_t primaryRays = 0;
    std::size_t chunks = 1;
    std::vector<std::size_t> atMost;  // chunks + 1 running totals: chunk c makes at most atMost[c + 1] - atMost[c]
    std::size_t chunkBegin(std::size_t c) const { return primaryRays * c / chunks; }
    std::size_t total() const { return atMost.back(); }
};
PassRayCounts passRayCounts(const SecondaryPass& pass, const std::vector<Hit>& primaryHits, ThreadPool& pool);

SecondaryRays makeSecondaryRays(const SecondaryPass& pass, const std::vector<Ray>& primary,
                                const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                ThreadPool& pool);
// ... with the pass's counts of these primary hits (passRayCounts) already at hand.
SecondaryRays makeSecondaryRays(const SecondaryPass& pass, const std::vector<Ray>& primary,
                                const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                const PassRayCounts& counts, ThreadPool& pool);

// A pass's slotCount slots before any hit: Hit{0, kNotTracedPrim} in each, filled in chunks
// on the pool (filledArray).
std::vector<Hit> notTracedSlots(std::uint64_t slotCount, ThreadPool* pool = nullptr);

// hits[i] into slot slotOf[i] of slotArrays[passOf[i]] (of slotArrays[0] where passOf is null),
// in chunks side by side on the pool (on the calling thread without one): each ray has its own
// slot. Throws InternalError where a slot lies past its array (nothing is written there).
// Not from a task of the same pool (ThreadPool::parallelFor does not nest).
void scatterToSlots(std::span<std::vector<Hit>> slotArrays, const std::uint32_t* slotOf, const std::uint16_t* passOf,
                    const Hit* hits, std::size_t count, ThreadPool* pool);

// The pass's result per slot: the traced hit (any hit: the visibility is exact), or
// Hit{0, kNotTracedPrim} where no ray was made. pool: the fill and scatter in chunks side by
// side (none: on the calling thread; not from a task of the same pool).
std::vector<Hit> hitsPerSlot(const SecondaryRays& rays, const std::vector<Hit>& traced, ThreadPool* pool = nullptr);

// The frame a pass's rays are traced as: any hit (frameGeometry finds their child order:
// shadow rays to a directional light share a direction, the others go every way). pool: its
// passes over the rays side by side (none: on the calling thread).
FrameGeometry secondaryFrame(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                             const std::vector<Ray>& rays, const Box& sceneBox, ThreadPool* pool = nullptr);
// A pass's rays (or a group of them) as a frame over the primary frame's triangles
// (secondaryFrame), with the primary frame's bound columns, triangle version and scene. pool:
// its passes over the rays side by side (none for a group traced on one worker of the pool).
FrameGeometry passFrame(const FrameGeometry& primary, const std::vector<Ray>& rays, ThreadPool* pool = nullptr);

}  // namespace dacrt
