#pragma once
// Occlusion and shadow rays several at a time (Google Highway, the best instruction set the
// machine has, chosen at run time): shared::occlusionRay's and shared::shadowRay's bits
// (secondary_rays.glsl), ray by ray. The same single-precision operations in the same order
// (an occlusion ray's rejection sampling run lane by lane until every lane has its point), so
// the same rays.
#include <cstdint>

#include "core/scene.hpp"

namespace dacrt {

// A batch of occlusion rays to make: ray j draws stream[j] from the surface of unit normal
// normal[.][j] whose rays start at origin[.][j] (shared::SurfaceSample, valid). Arrays of
// structures would need a gather per field; these load one vector each.
struct OcclusionBatch {
    static constexpr int kRays = 256;
    static constexpr int kPadding = 16;  // a vector's lanes past the last ray are read, not used
    alignas(64) std::uint32_t stream[kRays + kPadding];
    alignas(64) float normal[3][kRays + kPadding];
    alignas(64) float origin[3][kRays + kPadding];
    int count = 0;
};

// The batch's rays into out[0 .. batch.count - 1]: those of occlusionRay(surface, stream, seed,
// segmentLength).
void makeOcclusionRays(const OcclusionBatch& batch, std::uint32_t seed, float segmentLength, Ray* out);

// A batch of shadow rays to make: surface j (shared::SurfaceSample, valid) is point[.][j], its
// unit normal normal[.][j] and its rays' start origin[.][j].
struct ShadowBatch {
    static constexpr int kRays = 256;
    static constexpr int kPadding = 16;  // a vector's lanes past the last surface are read, not used
    alignas(64) float point[3][kRays + kPadding];
    alignas(64) float normal[3][kRays + kPadding];
    alignas(64) float origin[3][kRays + kPadding];
    int count = 0;
};

// shared::shadowRay(surface j, light) for every surface of the batch, lane by lane: the same
// float32 operations in the same order, so the same rays. The rays made, in surface order, go to
// out[0 ..] and their surfaces' numbers to surface[0 ..]; returns how many (a surface the light
// cannot reach makes none).
int makeShadowRays(const ShadowBatch& batch, const shared::ShadowLight& light, Ray* out, std::uint32_t* surface);

}  // namespace dacrt
