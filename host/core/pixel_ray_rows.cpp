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
#include "core/ray_fields-inl.h"

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
    const VF zero = hn::Zero(df), noHit = hn::Set(df, kNoHitT);
    const VF origin[3] = {hn::Set(df, pixels.origin.x), hn::Set(df, pixels.origin.y), hn::Set(df, pixels.origin.z)};

    // The ray's four 16-byte quarters, lane by lane (Ray: origin tmin, dir axes, invDir tmax,
    // shear pad).
    constexpr std::size_t kMost = hn::MaxLanes(df);
    HWY_ALIGN float storage[4][4 * kMost];
    float* const quarters[4] = {storage[0], storage[1], storage[2], storage[3]};
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
        for (int a = 0; a < 3; ++a)
            d[a] = ray_fields::HWY_NAMESPACE::FlushSmall(df, hn::DemoteTo(df, hn::Mul(direction[a], inverseLength)));
        if constexpr (kTile) {
            ray_fields::HWY_NAMESPACE::StoreOriginAndDirection(df, origin, zero, d, zero, quarters);
        } else {
            ray_fields::HWY_NAMESPACE::StoreRayQuarters(df, origin, zero, d, noHit, quarters);
        }
        ray_fields::HWY_NAMESPACE::CopyRayQuarters(quarters, made, kTile ? 2 : 4, out + i);
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
