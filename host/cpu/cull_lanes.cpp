// Compiled once per instruction set by Highway's foreach_target (this file includes itself),
// as simd_kernels.cpp is; HWY_DYNAMIC_DISPATCH picks the best one the machine supports.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "cpu/cull_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <cmath>
#include <cstddef>
#include <limits>

#include "cpu/cull_lanes.hpp"
#include "cpu/triangle_skips.hpp"

HWY_BEFORE_NAMESPACE();
namespace dacrt::simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// cellAlong, lanes at a time: std::max(0, x) is `0 < x ? x : 0` and std::min(x, m) is
// `m < x ? m : x`, written the same way so that NaN and signed zeros resolve as there.
template <class DF, class VF = hn::Vec<DF>>
HWY_INLINE hn::Vec<hn::RebindToSigned<DF>> cellsAlong(DF df, VF x, const GridAxes& grid, int k) {
    const VF zero = hn::Zero(df), last = hn::Set(df, float(grid.count[k] - 1));
    const VF scaled = hn::Mul(hn::Sub(x, hn::Set(df, grid.lo[k])), hn::Set(df, grid.scale[k]));
    const VF above = hn::IfThenElse(zero < scaled, scaled, zero);
    return hn::ConvertTo(hn::RebindToSigned<DF>(), hn::IfThenElse(last < above, last, above));
}

void CellsOfBoxes(const Bounds* bounds, std::uint32_t count, const GridAxes& grid, BoxCells& cells) {
    const hn::ScalableTag<float> df;
    const std::size_t n = hn::Lanes(df);
    static_assert(kCullBlock % 64 == 0, "whole vectors of up to 64 lanes fill the block");
    // Each box's six faces transposed into lanes in scalar code: the boxes are consecutive,
    // and gathers are the slower way here (simd_kernels.cpp, loadPerLane).
    alignas(64) float lo[3][64], hi[3][64];
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        for (std::size_t l = 0; l < n; ++l) {
            const Bounds& b = bounds[std::min<std::size_t>(i + l, count - 1)];
            for (int k = 0; k < 3; ++k) lo[k][l] = b.lo[grid.axis[k]], hi[k][l] = b.hi[grid.axis[k]];
        }
        for (int k = 0; k < 3; ++k) {
            hn::Store(cellsAlong(df, hn::Load(df, lo[k]), grid, k), hn::RebindToSigned<decltype(df)>(), cells.first[k] + i);
            hn::Store(cellsAlong(df, hn::Load(df, hi[k]), grid, k), hn::RebindToSigned<decltype(df)>(), cells.last[k] + i);
        }
    }
}

// floatBelow of float64 lanes, into float32 lanes (half as wide). For finite x only, which
// every point of a segment clipped to the scene box is: Highway's portable target (EMU128)
// demotes an infinity to FLT_MAX where the scalar float(x) gives the infinity.
template <class DD, class VD = hn::Vec<DD>>
HWY_INLINE hn::Vec<hn::Rebind<float, DD>> floatsBelow(DD dd, VD x) {
    const hn::Rebind<float, DD> df;
    const hn::Rebind<std::int32_t, DD> di;
    const auto f = hn::DemoteTo(df, x);
    // Whether the nearest float is above x, as a mask of the float lanes: through 1.0 or 0.0,
    // as Highway 1.0 converts no mask from 64-bit lanes to 32-bit ones.
    const auto above = hn::DemoteTo(di, hn::IfThenElseZero(hn::PromoteTo(dd, f) > x, hn::Set(dd, 1.0))) == hn::Set(di, 1);
    const auto bits = hn::BitCast(di, f);
    const auto zeroAsMinus = hn::IfThenElse(bits == hn::Zero(di), hn::Set(di, std::numeric_limits<std::int32_t>::min()), bits);
    const auto stepped = hn::Add(zeroAsMinus, hn::IfThenElse(zeroAsMinus < hn::Zero(di), hn::Set(di, 1), hn::Set(di, -1)));
    return hn::BitCast(df, hn::IfThenElse(above, stepped, bits));
}

void CellsNearPieceEnds(const glm::dvec3& origin, const glm::dvec3& dir, double t0, double t1, int pieces, double grow,
                        const GridAxes& grid, PieceEndCells& cells) {
    const hn::ScalableTag<double> dd;
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    const std::size_t n = hn::Lanes(dd);
    const auto start = hn::Set(dd, t0), end = hn::Set(dd, t1), length = hn::Set(dd, t1 - t0);
    const auto count = hn::Set(dd, double(pieces)), growLanes = hn::Set(dd, grow);
    for (int k = 0; k <= pieces; k += int(n)) {
        const auto ends = hn::Iota(dd, double(k));  // exact: small integers
        auto t = hn::Add(start, hn::Div(hn::Mul(length, ends), count));
        t = hn::IfThenElse(ends == hn::Zero(dd), start, hn::IfThenElse(ends == count, end, t));
        for (int a = 0; a < 3; ++a) {
            const int axis = grid.axis[a];
            const auto p = hn::Add(hn::Set(dd, origin[axis]), hn::Mul(t, hn::Set(dd, dir[axis])));
            const auto below = floatsBelow(dd, hn::Sub(p, growLanes));
            const auto above = hn::Neg(floatsBelow(dd, hn::Neg(hn::Add(p, growLanes))));
            hn::Store(below, df, cells.below[a] + k);
            hn::Store(above, df, cells.above[a] + k);
            hn::Store(cellsAlong(df, below, grid, a), di, cells.from[a] + k);
            hn::Store(cellsAlong(df, above, grid, a), di, cells.to[a] + k);
        }
    }
}

// facesAwayAlong in float64 lanes, its operations in its order: glm's cross (x.y y.z - y.y x.z
// and so on), glm's dot ((x + y) + z) and std::max over the edges' squares, which for finite
// vertices are never negative or NaN, so any order of the maximum gives the same value (and
// where a vertex is not finite, along is NaN and both answer false).
void FacingAwayAlong(const Triangle* triangles, std::uint32_t count, const glm::dvec3& direction, double reach,
                     const std::uint8_t* asked, std::uint8_t* away) {
    const hn::ScalableTag<double> dd;
    using VD = hn::Vec<decltype(dd)>;
    const std::size_t n = hn::Lanes(dd);
    const VD d[3] = {hn::Set(dd, direction.x), hn::Set(dd, direction.y), hn::Set(dd, direction.z)};
    const VD length = hn::Set(dd, glm::length(direction)), reachLanes = hn::Set(dd, reach);
    const VD perEdge = hn::Set(dd, kFacingPerEdge), reachTerm = hn::Set(dd, kFacingPerReach * reach);
    const VD zero = hn::Zero(dd);
    alignas(64) double v[3][3][32];
    alignas(64) std::uint8_t single[32];
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        const std::size_t here = std::min<std::size_t>(n, count - i);
        bool any = !asked;
        for (std::size_t l = 0; l < here && !any; ++l) any = asked[i + l] != 0;
        if (!any) {
            std::fill(away + i, away + i + here, std::uint8_t(0));
            continue;
        }
        for (std::size_t l = 0; l < n; ++l) {
            const Triangle& t = triangles[i + std::min(l, here - 1)];
            const glm::vec3* p[3] = {&t.v0, &t.v1, &t.v2};
            for (int k = 0; k < 3; ++k)
                for (int c = 0; c < 3; ++c) v[k][c][l] = double((*p[k])[c]);
            single[l] = t.cullBackFace != 0u;
        }
        VD e1[3], e2[3], e3[3];
        for (int c = 0; c < 3; ++c) {
            const VD p0 = hn::Load(dd, v[0][c]), p1 = hn::Load(dd, v[1][c]), p2 = hn::Load(dd, v[2][c]);
            e1[c] = hn::Sub(p1, p0);
            e2[c] = hn::Sub(p2, p0);
            e3[c] = hn::Sub(p2, p1);
        }
        const VD nx = hn::Sub(hn::Mul(e1[1], e2[2]), hn::Mul(e2[1], e1[2]));
        const VD ny = hn::Sub(hn::Mul(e1[2], e2[0]), hn::Mul(e2[2], e1[0]));
        const VD nz = hn::Sub(hn::Mul(e1[0], e2[1]), hn::Mul(e2[0], e1[1]));
        const VD along = hn::Div(hn::Add(hn::Add(hn::Mul(nx, d[0]), hn::Mul(ny, d[1])), hn::Mul(nz, d[2])), length);
        auto dot = [](const VD (&e)[3]) { return hn::Add(hn::Add(hn::Mul(e[0], e[0]), hn::Mul(e[1], e[1])), hn::Mul(e[2], e[2])); };
        const VD l2 = hn::Max(hn::Max(dot(e1), dot(e2)), dot(e3));
        const auto facesAway =
            hn::And(along > zero, hn::Div(along, reachLanes) > hn::Add(hn::Mul(perEdge, hn::Sqrt(l2)), reachTerm));
        alignas(8) std::uint8_t bits[8] = {};
        hn::StoreMaskBits(dd, facesAway, bits);
        for (std::size_t l = 0; l < here; ++l) away[i + l] = std::uint8_t(single[l] & (bits[l / 8] >> (l % 8)) & 1u);
    }
}

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::simd
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace dacrt::simd {

HWY_EXPORT(CellsOfBoxes);
HWY_EXPORT(CellsNearPieceEnds);
HWY_EXPORT(FacingAwayAlong);

void cellsOfBoxes(const Bounds* bounds, std::uint32_t count, const GridAxes& grid, BoxCells& cells) {
    HWY_DYNAMIC_DISPATCH(CellsOfBoxes)(bounds, count, grid, cells);
}

void cellsNearPieceEnds(const glm::dvec3& origin, const glm::dvec3& dir, double t0, double t1, int pieces, double grow,
                        const GridAxes& grid, PieceEndCells& cells) {
    HWY_DYNAMIC_DISPATCH(CellsNearPieceEnds)(origin, dir, t0, t1, pieces, grow, grid, cells);
}

void facingAwayAlong(const Triangle* triangles, std::uint32_t count, const glm::dvec3& direction, double reach,
                     const std::uint8_t* asked, std::uint8_t* away) {
    HWY_DYNAMIC_DISPATCH(FacingAwayAlong)(triangles, count, direction, reach, asked, away);
}

}  // namespace dacrt::simd
#endif
