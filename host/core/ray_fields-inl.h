// makeRay's float fields for a vector of rays, in Highway (included once per target by the
// SIMD ray makers: core/pixel_ray_rows.cpp, cpu/occlusion_ray_rows.cpp). The same operations
// as makeRay and shared::segmentRay (secondary_rays.glsl), lane by lane, so the same bits.
// Highway's per-target include guard: this file is compiled again for every target.
#if defined(DACRT_CORE_RAY_FIELDS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef DACRT_CORE_RAY_FIELDS_INL_H_
#undef DACRT_CORE_RAY_FIELDS_INL_H_
#else
#define DACRT_CORE_RAY_FIELDS_INL_H_
#endif

#include <cstdint>
#include <cstring>

#include <hwy/highway.h>

#include "core/scene.hpp"

HWY_BEFORE_NAMESPACE();
namespace dacrt::ray_fields {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Components below 2^-64 flushed to zero (+0), so that every 1/dir stays below 2^64.
template <class DF>
HWY_INLINE hn::Vec<DF> FlushSmall(DF df, hn::Vec<DF> d) {
    return hn::IfThenZeroElse(hn::Lt(hn::Abs(d), hn::Set(df, 0x1p-64f)), d);
}

// The rays' first two 16-byte quarters, lane by lane, into quarters[0] and quarters[1]
// (origin tmin, dir and the 32 bits after it: the axes, or anything for a tracer that reads
// the origin and direction alone).
template <class DF>
HWY_INLINE void StoreOriginAndDirection(DF df, const hn::Vec<DF> origin[3], hn::Vec<DF> tmin, const hn::Vec<DF> d[3],
                                        hn::Vec<DF> afterDir, float* const quarters[4]) {
    hn::StoreInterleaved4(origin[0], origin[1], origin[2], tmin, df, quarters[0]);
    hn::StoreInterleaved4(d[0], d[1], d[2], afterDir, df, quarters[1]);
}

// The rays' four 16-byte quarters, lane by lane, into quarters[q][4 * lane ..] (Ray: origin
// tmin, dir axes, invDir tmax, shear pad), from their origin, segment and flushed direction d:
// the reciprocals (0 where d is 0), the watertight test's axes (kz the largest |d|, the first
// of equals; (kx, ky) following it, swapped where d[kz] < 0) and shear.
template <class DF>
HWY_INLINE void StoreRayQuarters(DF df, const hn::Vec<DF> origin[3], hn::Vec<DF> tmin, const hn::Vec<DF> d[3],
                                 hn::Vec<DF> tmax, float* const quarters[4]) {
    using VF = hn::Vec<DF>;
    const hn::RebindToUnsigned<DF> du;
    const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
    const VF absD[3] = {hn::Abs(d[0]), hn::Abs(d[1]), hn::Abs(d[2])};
    const auto over0 = hn::Gt(absD[1], absD[0]);
    const auto over1 = hn::Gt(absD[2], hn::IfThenElse(over0, absD[1], absD[0]));
    const VF dz = hn::IfThenElse(over1, d[2], hn::IfThenElse(over0, d[1], d[0]));
    const VF dxUnswapped = hn::IfThenElse(over1, d[0], hn::IfThenElse(over0, d[2], d[1]));
    const VF dyUnswapped = hn::IfThenElse(over1, d[1], hn::IfThenElse(over0, d[0], d[2]));
    const auto negative = hn::Lt(dz, zero);
    const VF dx = hn::IfThenElse(negative, dyUnswapped, dxUnswapped);
    const VF dy = hn::IfThenElse(negative, dxUnswapped, dyUnswapped);
    const auto over0U = hn::RebindMask(du, over0), over1U = hn::RebindMask(du, over1);
    const auto negativeU = hn::RebindMask(du, negative);
    const auto u0 = hn::Zero(du), u1 = hn::Set(du, 1u), u2 = hn::Set(du, 2u);
    const auto kz = hn::IfThenElse(over1U, u2, hn::IfThenElse(over0U, u1, u0));
    const auto kxUnswapped = hn::IfThenElse(over1U, u0, hn::IfThenElse(over0U, u2, u1));
    const auto kyUnswapped = hn::IfThenElse(over1U, u1, hn::IfThenElse(over0U, u0, u2));
    const auto kx = hn::IfThenElse(negativeU, kyUnswapped, kxUnswapped);
    const auto ky = hn::IfThenElse(negativeU, kxUnswapped, kyUnswapped);
    const auto axes = hn::Or(kx, hn::Or(hn::ShiftLeft<2>(ky), hn::ShiftLeft<4>(kz)));
    VF inverse[3];
    for (int a = 0; a < 3; ++a) inverse[a] = hn::IfThenZeroElse(hn::Eq(d[a], zero), hn::Div(one, d[a]));
    StoreOriginAndDirection(df, origin, tmin, d, hn::BitCast(df, axes), quarters);
    hn::StoreInterleaved4(inverse[0], inverse[1], inverse[2], tmax, df, quarters[2]);
    hn::StoreInterleaved4(hn::Div(dx, dz), hn::Div(dy, dz), hn::Div(one, dz), zero, df, quarters[3]);
}

// Lanes 0 .. lanes - 1 of the quarters into out[0 ..], `parts` quarters of each ray (4: whole
// rays; 2: origin, tmin, dir and axes alone).
inline void CopyRayQuarters(const float* const quarters[4], int lanes, int parts, Ray* out) {
    for (int l = 0; l < lanes; ++l) {
        auto* ray = reinterpret_cast<unsigned char*>(&out[l]);
        for (int q = 0; q < parts; ++q) std::memcpy(ray + 16 * q, quarters[q] + 4 * l, 16);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::ray_fields
HWY_AFTER_NAMESPACE();

#endif  // per-target include guard
