// Compiled once per instruction set by Highway's foreach_target (this file includes itself);
// HWY_DYNAMIC_DISPATCH picks the best one the machine supports on first use.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/pixel_ray_rows.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/pixel_ray_rows.hpp"

HWY_BEFORE_NAMESPACE();
namespace dacrt::rows {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The lanes' pixel offsets within a 4x4 tile, lane l at (l % 4, l / 4).
alignas(64) constexpr double kTileColumn[16] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
alignas(64) constexpr double kTileRow[16] = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};

// One lane per pixel: the direction in double, as PixelRays::unrounded and makeRay compute it,
// then the ray's float fields in a float vector of as many lanes. kTile: the lanes of a 4x4
// tile, each its own row, and the origin and direction alone; else a row's span, whole rays.
template <bool kTile>
HWY_INLINE int PerspectiveRays(const PerspectivePixels& pixels, int x0, int y0, int count, Ray* out) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::uint32_t, decltype(dd)> du;
    const int lanes = int(hn::Lanes(dd));
    using VD = hn::Vec<decltype(dd)>;
    using VF = hn::Vec<decltype(df)>;

    const VD smallestNormal = hn::Set(dd, std::numeric_limits<double>::min());
    const VD largest = hn::Set(dd, std::numeric_limits<double>::max());
    const VD two = hn::Set(dd, 2.0), one = hn::Set(dd, 1.0);
    const VD offsetX = hn::Set(dd, pixels.offset.x), offsetY = hn::Set(dd, pixels.offset.y);
    const VD width = hn::Set(dd, pixels.width), height = hn::Set(dd, pixels.height);
    const VD halfHeight = hn::Set(dd, pixels.halfHeight), aspect = hn::Set(dd, pixels.aspect);
    const VD right[3] = {hn::Set(dd, pixels.right.x), hn::Set(dd, pixels.right.y), hn::Set(dd, pixels.right.z)};
    const VD forward[3] = {hn::Set(dd, pixels.forward.x), hn::Set(dd, pixels.forward.y), hn::Set(dd, pixels.forward.z)};
    const VD up[3] = {hn::Set(dd, pixels.up.x), hn::Set(dd, pixels.up.y), hn::Set(dd, pixels.up.z)};
    // A row's sy up, once: sy = (1 - 2 (y + offset) / height) halfHeight.
    const double rowSy = (1.0 - 2.0 * (y0 + pixels.offset.y) / pixels.height) * pixels.halfHeight;
    const VD rowUp[3] = {hn::Set(dd, rowSy * pixels.up.x), hn::Set(dd, rowSy * pixels.up.y),
                         hn::Set(dd, rowSy * pixels.up.z)};
    const VF zero = hn::Zero(df), oneF = hn::Set(df, 1.0f), tiny = hn::Set(df, 0x1p-64f);
    const VF origin[3] = {hn::Set(df, pixels.origin.x), hn::Set(df, pixels.origin.y), hn::Set(df, pixels.origin.z)};
    const VF noHit = hn::Set(df, kNoHitT);
    const auto u0 = hn::Zero(du), u1 = hn::Set(du, 1u), u2 = hn::Set(du, 2u);

    // The ray's four 16-byte quarters, lane by lane (Ray: origin tmin, dir axes, invDir tmax,
    // shear pad).
    constexpr std::size_t kMost = hn::MaxLanes(df);
    HWY_ALIGN float quarters[4][4 * kMost];
    for (int i = 0; i < count; i += lanes) {
        const int valid = std::min(lanes, count - i);
        // sx = (2 (x + offset) / width - 1) halfHeight aspect; direction = forward + (sx right + sy up).
        VD x, offPlaneUp[3];
        if constexpr (kTile) {
            x = hn::Add(hn::Set(dd, double(x0)), hn::LoadU(dd, kTileColumn + i));
            const VD y = hn::Add(hn::Set(dd, double(y0)), hn::LoadU(dd, kTileRow + i));
            const VD sy = hn::Mul(hn::Sub(one, hn::Div(hn::Mul(two, hn::Add(y, offsetY)), height)), halfHeight);
            for (int a = 0; a < 3; ++a) offPlaneUp[a] = hn::Mul(sy, up[a]);
        } else {
            x = hn::Iota(dd, double(x0 + i));
            for (int a = 0; a < 3; ++a) offPlaneUp[a] = rowUp[a];
        }
        const VD sx = hn::Mul(hn::Mul(hn::Sub(hn::Div(hn::Mul(two, hn::Add(x, offsetX)), width), one), halfHeight), aspect);
        VD direction[3];
        for (int a = 0; a < 3; ++a) direction[a] = hn::Add(forward[a], hn::Add(hn::Mul(sx, right[a]), offPlaneUp[a]));
        // glm::normalize: direction * (1 / sqrt(dot)), dot = (x x + y y) + z z.
        const VD dot = hn::Add(hn::Add(hn::Mul(direction[0], direction[0]), hn::Mul(direction[1], direction[1])),
                               hn::Mul(direction[2], direction[2]));
        // makeRay refuses a direction not finite or zero, and scales one whose squares overflow
        // or underflow: those lanes are left to it.
        const auto fine = hn::And(hn::And(hn::IsFinite(direction[0]), hn::IsFinite(direction[1])),
                                  hn::And(hn::IsFinite(direction[2]), hn::And(hn::Ge(dot, smallestNormal), hn::Le(dot, largest))));
        // The rays before the first lane left to makeRay (lanes past the span do not count).
        const auto refused = hn::AndNot(fine, hn::FirstN(dd, std::size_t(valid)));
        const intptr_t firstRefused = hn::FindFirstTrue(dd, refused);
        const int made = firstRefused < 0 ? valid : int(firstRefused);
        if (made == 0) return i;
        const VD inverseLength = hn::Div(one, hn::Sqrt(dot));
        VF d[3];
        for (int a = 0; a < 3; ++a) {
            d[a] = hn::DemoteTo(df, hn::Mul(direction[a], inverseLength));
            d[a] = hn::IfThenZeroElse(hn::Lt(hn::Abs(d[a]), tiny), d[a]);  // makeRay's flush below 2^-64
        }
        hn::StoreInterleaved4(origin[0], origin[1], origin[2], zero, df, quarters[0]);
        if constexpr (kTile) {
            hn::StoreInterleaved4(d[0], d[1], d[2], zero, df, quarters[1]);
        } else {
            // makeRay's axes: kz the largest |d| (the first of equals), (kx, ky) following it,
            // swapped where d[kz] < 0.
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
            const auto kz = hn::IfThenElse(over1U, u2, hn::IfThenElse(over0U, u1, u0));
            const auto kxUnswapped = hn::IfThenElse(over1U, u0, hn::IfThenElse(over0U, u2, u1));
            const auto kyUnswapped = hn::IfThenElse(over1U, u1, hn::IfThenElse(over0U, u0, u2));
            const auto kx = hn::IfThenElse(negativeU, kyUnswapped, kxUnswapped);
            const auto ky = hn::IfThenElse(negativeU, kxUnswapped, kyUnswapped);
            const auto axes = hn::Or(kx, hn::Or(hn::ShiftLeft<2>(ky), hn::ShiftLeft<4>(kz)));
            VF inverse[3];
            for (int a = 0; a < 3; ++a) inverse[a] = hn::IfThenZeroElse(hn::Eq(d[a], zero), hn::Div(oneF, d[a]));
            hn::StoreInterleaved4(d[0], d[1], d[2], hn::BitCast(df, axes), df, quarters[1]);
            hn::StoreInterleaved4(inverse[0], inverse[1], inverse[2], noHit, df, quarters[2]);
            hn::StoreInterleaved4(hn::Div(dx, dz), hn::Div(dy, dz), hn::Div(oneF, dz), zero, df, quarters[3]);
        }
        constexpr int kQuarters = kTile ? 2 : 4;
        for (int l = 0; l < made; ++l) {
            auto* ray = reinterpret_cast<unsigned char*>(&out[i + l]);
            for (int q = 0; q < kQuarters; ++q) std::memcpy(ray + 16 * q, &quarters[q][4 * l], 16);
        }
        if (made < valid) return i + made;
    }
    return count;
}

int PerspectiveRowRays(const PerspectivePixels& pixels, int y, int x0, int count, Ray* out) {
    return PerspectiveRays<false>(pixels, x0, y, count, out);
}

int PerspectiveTileDirections(const PerspectivePixels& pixels, int x0, int y0, Ray* out) {
    return PerspectiveRays<true>(pixels, x0, y0, 16, out);
}

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::rows
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace dacrt {
namespace rows {
HWY_EXPORT(PerspectiveRowRays);
HWY_EXPORT(PerspectiveTileDirections);
}  // namespace rows

int perspectiveRowRays(const PerspectivePixels& pixels, int y, int x0, int count, Ray* out) {
    return HWY_DYNAMIC_DISPATCH(rows::PerspectiveRowRays)(pixels, y, x0, count, out);
}

int perspectiveTileDirections(const PerspectivePixels& pixels, int x0, int y0, Ray* out) {
    return HWY_DYNAMIC_DISPATCH(rows::PerspectiveTileDirections)(pixels, x0, y0, out);
}

static_assert(sizeof(Ray) == 64, "perspectiveRowRays writes a ray as four 16-byte quarters");

}  // namespace dacrt
#endif
