// Compiled once per instruction set by Highway's foreach_target (this file includes itself);
// HWY_DYNAMIC_DISPATCH picks the best one the machine supports on first use.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "cpu/occlusion_ray_rows.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>

#include "core/ray_fields-inl.h"
#include "cpu/occlusion_ray_rows.hpp"
#include "cpu/secondary_rays.hpp"

HWY_BEFORE_NAMESPACE();
namespace dacrt::occlusion {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// exact_math.glsl's pcgHash, lane by lane.
template <class DU>
HWY_INLINE hn::Vec<DU> PcgHash(DU du, hn::Vec<DU> v) {
    const auto state = hn::Add(hn::Mul(v, hn::Set(du, 747796405u)), hn::Set(du, 2891336453u));
    const auto shift = hn::Add(hn::ShiftRight<28>(state), hn::Set(du, 4u));
    const auto word = hn::Mul(hn::Xor(hn::Shr(state, shift), state), hn::Set(du, 277803737u));
    return hn::Xor(hn::ShiftRight<22>(word), word);
}

// exact_math.glsl's unitInterval: the top 24 bits as a float in [0, 1), exactly.
template <class DF, class DU>
HWY_INLINE hn::Vec<DF> UnitInterval(DF df, DU, hn::Vec<DU> bits) {
    const hn::RebindToSigned<DF> di;
    return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(bits))), hn::Set(df, 5.9604644775390625e-08f));
}

void MakeOcclusionRays(const OcclusionBatch& batch, std::uint32_t seed, float segmentLength, Ray* out) {
    const hn::ScalableTag<float> df;
    const hn::RebindToUnsigned<decltype(df)> du;
    using VF = hn::Vec<decltype(df)>;
    const int lanes = int(hn::Lanes(df));
    const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f), minusOne = hn::Set(df, -1.0f), two = hn::Set(df, 2.0f);
    const VF tmax = hn::Set(df, segmentLength), tmin = hn::Set(df, shared::kSegmentStart);
    const auto seedHash = hn::Set(du, shared::pcgHash(seed));
    constexpr std::size_t kMost = hn::MaxLanes(df);
    HWY_ALIGN float storage[4][4 * kMost];
    float* const quarters[4] = {storage[0], storage[1], storage[2], storage[3]};
    for (int i = 0; i < batch.count; i += lanes) {
        const int valid = std::min(lanes, batch.count - i);
        // The disk point: rejection sampling of the square, each lane until its first point
        // inside (at most 16 tries, then the pole), lanes past the batch done from the start.
        const auto hashed = PcgHash(du, hn::Xor(hn::LoadU(du, batch.stream + i), seedHash));
        VF x = zero, y = zero, rr = zero;
        auto done = hn::Not(hn::FirstN(df, std::size_t(valid)));
        for (std::uint32_t attempt = 0; attempt < 16u && !hn::AllTrue(df, done); ++attempt) {
            const auto first = hn::Add(hashed, hn::Set(du, 2u * attempt));
            const VF cx = hn::Sub(hn::Mul(two, UnitInterval(df, du, PcgHash(du, first))), one);
            const VF cy = hn::Sub(hn::Mul(two, UnitInterval(df, du, PcgHash(du, hn::Add(first, hn::Set(du, 1u))))), one);
            const VF cr = hn::Add(hn::Mul(cx, cx), hn::Mul(cy, cy));
            const auto inside = hn::AndNot(done, hn::Lt(cr, one));
            x = hn::IfThenElse(inside, cx, x);
            y = hn::IfThenElse(inside, cy, y);
            rr = hn::IfThenElse(inside, cr, rr);
            done = hn::Or(done, inside);
        }
        const VF zz = hn::Sub(one, rr);
        const VF z = hn::IfThenElse(hn::Gt(zz, zero), hn::Sqrt(zz), zero);
        // Duff et al.'s tangent frame about the normal, then the point lifted to the hemisphere.
        const VF n[3] = {hn::LoadU(df, batch.normal[0] + i), hn::LoadU(df, batch.normal[1] + i),
                         hn::LoadU(df, batch.normal[2] + i)};
        const VF side = hn::IfThenElse(hn::Ge(n[2], zero), one, minusOne);
        const VF a = hn::Div(minusOne, hn::Add(side, n[2]));
        const VF b = hn::Mul(hn::Mul(n[0], n[1]), a);
        const VF tangent[3] = {hn::Add(one, hn::Mul(hn::Mul(hn::Mul(side, n[0]), n[0]), a)), hn::Mul(side, b),
                               hn::Mul(hn::Neg(side), n[0])};
        const VF bitangent[3] = {b, hn::Add(side, hn::Mul(hn::Mul(n[1], n[1]), a)), hn::Neg(n[1])};
        VF d[3];
        for (int c = 0; c < 3; ++c)
            d[c] = ray_fields::HWY_NAMESPACE::FlushSmall(
                df, hn::Add(hn::Add(hn::Mul(tangent[c], x), hn::Mul(bitangent[c], y)), hn::Mul(n[c], z)));
        const VF origin[3] = {hn::LoadU(df, batch.origin[0] + i), hn::LoadU(df, batch.origin[1] + i),
                              hn::LoadU(df, batch.origin[2] + i)};
        ray_fields::HWY_NAMESPACE::StoreRayQuarters(df, origin, tmin, d, tmax, quarters);
        ray_fields::HWY_NAMESPACE::CopyRayQuarters(quarters, valid, 4, out + i);
    }
}

// shared::dot3 lane by lane: (a.x b.x + a.y b.y) + a.z b.z.
template <class VF>
HWY_INLINE VF Dot3(const VF (&a)[3], const VF (&b)[3]) {
    return hn::Add(hn::Add(hn::Mul(a[0], b[0]), hn::Mul(a[1], b[1])), hn::Mul(a[2], b[2]));
}

int MakeShadowRays(const ShadowBatch& batch, const shared::ShadowLight& light, Ray* out, std::uint32_t* surface) {
    const hn::ScalableTag<float> df;
    using VF = hn::Vec<decltype(df)>;
    const int lanes = int(hn::Lanes(df));
    const bool directional = light.type == shared::kLightDirectional;
    const bool spot = light.type == shared::kLightSpot;
    const bool ranged = light.range > 0.0f;
    const VF zero = hn::Zero(df);
    const VF position[3] = {hn::Set(df, light.position.x), hn::Set(df, light.position.y), hn::Set(df, light.position.z)};
    const VF shining[3] = {hn::Set(df, light.direction.x), hn::Set(df, light.direction.y), hn::Set(df, light.direction.z)};
    const VF towardLight[3] = {hn::Neg(shining[0]), hn::Neg(shining[1]), hn::Neg(shining[2])};
    const VF rangeSquared = hn::Set(df, light.range * light.range);
    const VF cosOuterSquared = hn::Set(df, light.cosOuterSquared);
    const VF smallest = hn::Set(df, shared::kSmallestDirection);
    const VF tmin = hn::Set(df, shared::kSegmentStart), tmax = hn::Set(df, shared::shadowSegmentEnd(light));
    constexpr std::size_t kMost = hn::MaxLanes(df);
    HWY_ALIGN float storage[4][4 * kMost];
    float* const quarters[4] = {storage[0], storage[1], storage[2], storage[3]};
    int made = 0;
    for (int i = 0; i < batch.count; i += lanes) {
        const int valid = std::min(lanes, batch.count - i);
        VF point[3], normal[3], origin[3];
        for (int c = 0; c < 3; ++c) {
            point[c] = hn::LoadU(df, batch.point[c] + i);
            normal[c] = hn::LoadU(df, batch.normal[c] + i);
            origin[c] = hn::LoadU(df, batch.origin[c] + i);
        }
        // shadowRay's tests in its order: the surface faces the light, then (point and spot
        // lights) the range and the cone, then a direction long enough to make a ray of.
        VF toLight[3], d[3];
        for (int c = 0; c < 3; ++c) {
            toLight[c] = directional ? towardLight[c] : hn::Sub(position[c], point[c]);
            d[c] = directional ? towardLight[c] : hn::Sub(position[c], origin[c]);
        }
        auto reaches = hn::And(hn::FirstN(df, std::size_t(valid)), hn::Gt(Dot3(normal, toLight), zero));
        if (!directional) {
            const VF distanceSquared = Dot3(toLight, toLight);
            if (ranged) reaches = hn::AndNot(hn::Gt(distanceSquared, rangeSquared), reaches);
            if (spot) {
                const VF along = hn::Neg(Dot3(shining, toLight));
                const auto outside = hn::Or(hn::Not(hn::Gt(along, zero)),
                                            hn::Lt(hn::Mul(along, along), hn::Mul(cosOuterSquared, distanceSquared)));
                reaches = hn::AndNot(outside, reaches);
            }
        }
        const VF largest = hn::Max(hn::Abs(d[0]), hn::Max(hn::Abs(d[1]), hn::Abs(d[2])));
        reaches = hn::AndNot(hn::Lt(largest, smallest), reaches);
        if (hn::AllFalse(df, reaches)) continue;
        for (int c = 0; c < 3; ++c) d[c] = ray_fields::HWY_NAMESPACE::FlushSmall(df, d[c]);
        ray_fields::HWY_NAMESPACE::StoreRayQuarters(df, origin, tmin, d, tmax, quarters);
        alignas(8) std::uint8_t bits[8] = {};
        hn::StoreMaskBits(df, reaches, bits);
        std::uint32_t mask = std::uint32_t(bits[0]) | std::uint32_t(bits[1]) << 8;
        for (; mask; mask &= mask - 1) {
            const int l = __builtin_ctz(mask);
            const float* const lane[4] = {quarters[0] + 4 * l, quarters[1] + 4 * l, quarters[2] + 4 * l, quarters[3] + 4 * l};
            ray_fields::HWY_NAMESPACE::CopyRayQuarters(lane, 1, 4, out + made);
            surface[made++] = std::uint32_t(i + l);
        }
    }
    return made;
}

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::occlusion
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace dacrt {
namespace occlusion {
HWY_EXPORT(MakeOcclusionRays);
HWY_EXPORT(MakeShadowRays);
}  // namespace occlusion

void makeOcclusionRays(const OcclusionBatch& batch, std::uint32_t seed, float segmentLength, Ray* out) {
    HWY_DYNAMIC_DISPATCH(occlusion::MakeOcclusionRays)(batch, seed, segmentLength, out);
}

int makeShadowRays(const ShadowBatch& batch, const shared::ShadowLight& light, Ray* out, std::uint32_t* surface) {
    return HWY_DYNAMIC_DISPATCH(occlusion::MakeShadowRays)(batch, light, out, surface);
}

}  // namespace dacrt
#endif
