#pragma once
// The pass cull's arithmetic (pass_cull.hpp) in SIMD lanes, through Google Highway as the DACRT
// kernels are (simd_kernels.hpp): the cells near the ends of a ray's pieces, in float64 lanes,
// when the grid is marked; the cells a triangle's bounds cover, in float32 lanes, and the
// back-face test along a shared direction, in float64 lanes, when the triangles are culled.
// Each lane computes the scalar rule's IEEE operations in the same order, with the same
// min/max operand order and no contraction, so its answers are the scalar ones bit for bit
// (tests/cpu/test_simd_kernels.cpp runs both side by side on every compiled target).
#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

#include "core/scene.hpp"

namespace dacrt::simd {

// A grid of count[k] cells along its axis k, which is the scene's axis axis[k], starting at
// lo[k], scale[k] cells per unit (0 on a flat axis).
struct GridAxes {
    int axis[3] = {0, 1, 2};
    int count[3] = {1, 1, 1};
    float lo[3] = {};
    float scale[3] = {};
};

// The cell of the grid's axis k holding x, clamped to the grid: the rule. Monotone in x (each
// rounding and the clamp are), so boxes that overlap get cell ranges that overlap. std::max
// with 0 first: an infinite x on a flat axis (scale 0) gives NaN, which it turns into 0.
inline int cellAlong(const GridAxes& grid, float x, int k) {
    return int(std::min(std::max(0.0f, (x - grid.lo[k]) * grid.scale[k]), float(grid.count[k] - 1)));
}

// The float nearest to x, stepped once towards -inf where it is above x: no float lies between
// it and x (the rule; -FLT_MAX steps to -inf, which cellAlong clamps as it would FLT_MAX's
// cell). Without branches, a mask picking the step: whether one is needed is a coin toss
// that a branch predictor loses.
inline float floatBelow(double x) {
    const float f = float(x);
    const std::int32_t bits = std::bit_cast<std::int32_t>(f);
    const std::int32_t zeroAsMinus = bits == 0 ? std::numeric_limits<std::int32_t>::min() : bits;  // +0 steps as -0
    const std::int32_t stepped = zeroAsMinus + (zeroAsMinus < 0 ? 1 : -1);
    const std::int32_t step = -std::int32_t(double(f) > x);
    return std::bit_cast<float>((stepped & step) | (bits & ~step));
}
// The same towards +inf: a float no less than x.
inline float floatAbove(double x) { return -floatBelow(-x); }

// The point of parameter t_k at end k of `pieces` equal pieces of the segment [t0, t1] of
// origin + t dir (t_0 = t0, t_pieces = t1; the rule for the ends between, in float64).
inline double pieceEnd(double t0, double t1, int k, int pieces) {
    return k == 0 ? t0 : k == pieces ? t1 : t0 + (t1 - t0) * double(k) / double(pieces);
}

// The most pieces a ray's segment is cut into, and what a call gives for each end e along
// the grid's axis k: the bounds below[k][e] and above[k][e] and their cells from[k][e] and
// to[k][e] (the bounds are what the cells are of; the tests read them bit for bit).
constexpr int kMostPieces = 512;
struct PieceEndCells {
    alignas(64) std::int32_t from[3][kMostPieces + 64];
    alignas(64) std::int32_t to[3][kMostPieces + 64];
    alignas(64) float below[3][kMostPieces + 64];
    alignas(64) float above[3][kMostPieces + 64];
};
// The cells near each end k = 0 .. pieces (1 <= pieces <= kMostPieces) of the segment:
// p = origin + pieceEnd(t0, t1, k, pieces) dir, and along the grid's axis k, from the cell of
// floatBelow(p[axis] - grow) to that of floatAbove(p[axis] + grow) (cellAlong): the cells of
// the box around p grown by `grow`, each bound rounded outwards.
void cellsNearPieceEnds(const glm::dvec3& origin, const glm::dvec3& dir, double t0, double t1, int pieces, double grow,
                        const GridAxes& grid, PieceEndCells& cells);

// The kernels take the triangles of a pass in blocks of at most this many, whose answers stay
// in the first level of cache until the caller reads them.
constexpr std::uint32_t kCullBlock = 256;

// The cells box i of a block covers along the grid's axis k: first[k][i] to last[k][i].
struct BoxCells {
    alignas(64) std::int32_t first[3][kCullBlock];
    alignas(64) std::int32_t last[3][kCullBlock];
};

// cellAlong of bounds[i].lo and bounds[i].hi on each of the grid's axes, i < count <= kCullBlock.
void cellsOfBoxes(const Bounds* bounds, std::uint32_t count, const GridAxes& grid, BoxCells& cells);

// away[i] = 1 where triangles[i] is single-sided and facesAwayAlong(triangles[i], direction,
// reach) (triangle_skips.hpp), else 0, for i < count <= kCullBlock. Where `asked` is given, a
// vector of lanes none of which asked[i] names is not computed (0): the triangles the caller
// has already dropped are not read.
void facingAwayAlong(const Triangle* triangles, std::uint32_t count, const glm::dvec3& direction, double reach,
                     const std::uint8_t* asked, std::uint8_t* away);

}  // namespace dacrt::simd
