// Compiled once per instruction set by Highway's foreach_target (this file includes itself);
// HWY_DYNAMIC_DISPATCH picks the best one the machine supports on first use.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "cpu/simd_kernels.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "cpu/predicates.hpp"
#include "cpu/ray_packet.hpp"
#include "cpu/simd_kernels.hpp"

#ifndef DACRT_SIMD_COMPRESS_TABLE
#define DACRT_SIMD_COMPRESS_TABLE
namespace dacrt::simd {
// For each 8-bit lane mask, the indices of its set lanes in order: the permutation that
// compresses a vector of up to 8 lanes. Static, so no target copies it per call (Highway
// 1.0.3's own table for AVX2 is a local constant that GCC 12 rebuilds on the stack every
// time: 1 KiB per compress, the whole cost of the AVX2 partitions).
struct CompressTable {
    std::uint8_t lanes[256][8];
};
constexpr CompressTable makeCompressTable() {
    CompressTable t{};
    for (int mask = 0; mask < 256; ++mask) {
        int k = 0;
        for (int lane = 0; lane < 8; ++lane)
            if (mask & (1 << lane)) t.lanes[mask][k++] = std::uint8_t(lane);
    }
    return t;
}
alignas(64) static constexpr CompressTable kCompressTable = makeCompressTable();
}  // namespace dacrt::simd
#endif

HWY_BEFORE_NAMESPACE();
namespace dacrt::simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DU = hn::RebindToUnsigned<DF>;
using DI = hn::RebindToSigned<DF>;
using VF = hn::Vec<DF>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;

// shared::min(a, b) is `b < a ? b : a` and shared::max(a, b) is `a < b ? b : a`: written the
// same way, equal operands of different sign (+0, -0) resolve as in the scalar code.
// On x86, MINPS(x, y) is `x < y ? x : y` and MAXPS(x, y) is `x > y ? x : y` (y where either is
// NaN or both are zeros), so with the operands swapped each is one instruction for the
// comparison and the blend, bit for bit.
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL || HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_SSE4 || \
    HWY_TARGET == HWY_SSSE3
HWY_INLINE VF minLike(VF a, VF b) { return hn::Min(b, a); }
HWY_INLINE VF maxLike(VF a, VF b) { return hn::Max(b, a); }
#else
HWY_INLINE VF minLike(VF a, VF b) { return hn::IfThenElse(b < a, b, a); }
HWY_INLINE VF maxLike(VF a, VF b) { return hn::IfThenElse(a < b, b, a); }
#endif

// The lanes of v that m selects, first and in order (the rest unspecified).
HWY_INLINE VU compressIds(VU v, hn::Mask<DU> m) {
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
    return hn::Compress(v, m);  // vpcompressd, register form
#else
    const DU du;
    if constexpr (hn::MaxLanes(du) == 1) {
        return v;
    } else {
        static_assert(hn::MaxLanes(du) <= 8);
        std::uint8_t bits[8] = {};
        hn::StoreMaskBits(du, m, bits);
        const hn::Rebind<std::uint8_t, DU> d8;
        const VU lanes = hn::PromoteTo(du, hn::LoadU(d8, kCompressTable.lanes[bits[0]]));
        return hn::TableLookupLanes(v, hn::IndicesFromVec(du, hn::BitCast(hn::RebindToSigned<DU>(), lanes)));
    }
#endif
}

// The floats base[id * kStride + offset] of the ids in idLanes, a vector of them, with a plain
// load per lane: on this project's AMD Zen 5 VM, AVX-512's gathers cost more than the loads
// (Intel's Downfall mitigation slows gathers too); docs/cpu-reference.md, "Loads per lane".
template <std::size_t kStride>
HWY_INLINE VF loadPerLane(const float* base, const std::uint32_t* idLanes, std::size_t offset) {
    const DF df;
    alignas(64) float lanes[64];
    for (std::size_t l = 0; l < hn::Lanes(df); ++l) lanes[l] = base[std::size_t(idLanes[l]) * kStride + offset];
    return hn::Load(df, lanes);
}

// Floats offset to offset + 3 of each lane's record of kStride floats (base[id * kStride +
// offset + k] in fields[k]: a Ray's 16, a Triangle's 12), with one 128-bit load per lane and a
// 4x4 transpose in each block, where a vector holds whole blocks of four lanes: a quarter of
// the loads of loadPerLane, whose inserts were most of the ray filter's instructions.
template <std::size_t kOffset, std::size_t kStride = 16>
HWY_INLINE void loadQuadPerLane(const float* base, const std::uint32_t* idLanes, VF fields[4]) {
    static_assert(kOffset + 4 <= kStride);
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL || HWY_TARGET == HWY_AVX2
    const DF df;
    const hn::Repartition<double, DF> dd;
    auto quad = [&](std::size_t lane) { return _mm_loadu_ps(base + std::size_t(idLanes[lane]) * kStride + kOffset); };
    // blocks[j]'s block k holds lane 4k + j's four floats.
    VF blocks[4];
    for (std::size_t j = 0; j < 4; ++j) {
#if HWY_TARGET == HWY_AVX2
        blocks[j] = VF{_mm256_insertf128_ps(_mm256_castps128_ps256(quad(j)), quad(4 + j), 1)};
#else
        __m512 v = _mm512_castps128_ps512(quad(j));
        v = _mm512_insertf32x4(v, quad(4 + j), 1);
        v = _mm512_insertf32x4(v, quad(8 + j), 2);
        blocks[j] = VF{_mm512_insertf32x4(v, quad(12 + j), 3)};
#endif
    }
    const auto t0 = hn::BitCast(dd, hn::InterleaveLower(blocks[0], blocks[1]));
    const auto t1 = hn::BitCast(dd, hn::InterleaveUpper(df, blocks[0], blocks[1]));
    const auto t2 = hn::BitCast(dd, hn::InterleaveLower(blocks[2], blocks[3]));
    const auto t3 = hn::BitCast(dd, hn::InterleaveUpper(df, blocks[2], blocks[3]));
    fields[0] = hn::BitCast(df, hn::InterleaveLower(t0, t2));
    fields[1] = hn::BitCast(df, hn::InterleaveUpper(dd, t0, t2));
    fields[2] = hn::BitCast(df, hn::InterleaveLower(t1, t3));
    fields[3] = hn::BitCast(df, hn::InterleaveUpper(dd, t1, t3));
#else
    for (std::size_t k = 0; k < 4; ++k) fields[k] = loadPerLane<kStride>(base, idLanes, kOffset + k);
#endif
}

// Ids that pass first (compressed in place: the write position never passes the read
// position), the others through scratch behind them. Both keep their order. Each compressed
// vector is stored whole: its lanes past the count land on ids already read, or on the
// scratch's slack, never past the range (blended stores would not, but AMD runs AVX2's
// masked stores in microcode, and some Zen generations AVX-512's compressing stores).
// passes(v, lanes) tests the ids of v, which lanes holds in memory too: loads per lane take
// their index from there rather than extract it from the vector, lane by lane.
template <class Passes>
HWY_INLINE std::uint32_t stablePartition(std::uint32_t* ids, std::uint32_t count, std::uint32_t* scratch,
                                         const Passes& passes) {
    const DU du;
    const std::size_t n = hn::Lanes(du);
    std::size_t kept = 0, moved = 0, i = 0;
    for (; i + n <= count; i += n) {
        const VU v = hn::LoadU(du, ids + i);
        const auto m = passes(v, ids + i);
        const std::size_t passing = hn::CountTrue(du, m);
        hn::StoreU(compressIds(v, m), du, ids + kept);
        hn::StoreU(compressIds(v, hn::Not(m)), du, scratch + moved);
        kept += passing;
        moved += n - passing;
    }
    if (i < count) {
        // The tail through local copies: no access past the range (a neighbour's, or the end
        // of the array); the idle lanes repeat the range's first tail id, which this caller
        // owns (another worker may be writing the hit of any other ray, id 0's included).
        alignas(64) std::uint32_t tail[64], pass[64], fail[64];
        const std::size_t rest = count - i;
        std::fill(tail, tail + 64, ids[i]);
        std::copy(ids + i, ids + count, tail);
        const VU v = hn::Load(du, tail);
        const auto valid = hn::FirstN(du, rest);
        const auto m = hn::And(passes(v, tail), valid);
        const std::size_t passing = hn::CountTrue(du, m);
        hn::Store(compressIds(v, m), du, pass);
        hn::Store(compressIds(v, hn::AndNot(m, valid)), du, fail);
        std::copy(pass, pass + passing, ids + kept);
        std::copy(fail, fail + (rest - passing), scratch + moved);
        kept += passing;
        moved += rest - passing;
    }
    std::copy(scratch, scratch + moved, ids + kept);
    return std::uint32_t(kept);
}

// shared::slabInterval for lanes whose invDir is not 0 (no ray parallel to the slab): the
// interval between the slab's two faces, without the parallel case's selects.
HWY_INLINE void slabIntervalCrossing(VF origin, VF invDir, float lo, float hi, VF& tNear, VF& tFar) {
    const DF df;
    const VF t0 = hn::Mul(hn::Sub(hn::Set(df, lo), origin), invDir);
    const VF t1 = hn::Mul(hn::Sub(hn::Set(df, hi), origin), invDir);
    tNear = minLike(t0, t1);
    tFar = maxLike(t0, t1);
}

// shared::slabInterval, lane by lane: the crossing interval, or for a lane parallel to the
// slab every t (origin inside) or none.
HWY_INLINE void slabInterval(VF origin, VF invDir, float lo, float hi, VF& tNear, VF& tFar) {
    const DF df;
    slabIntervalCrossing(origin, invDir, lo, hi, tNear, tFar);
    const MF parallel = invDir == hn::Zero(df);
    const MF inside = hn::And(origin >= hn::Set(df, lo), origin <= hn::Set(df, hi));
    const VF none = hn::Set(df, kNoHitT), all = hn::Set(df, -kNoHitT);
    tNear = hn::IfThenElse(parallel, hn::IfThenElse(inside, all, none), tNear);
    tFar = hn::IfThenElse(parallel, hn::IfThenElse(inside, none, all), tFar);
}

// ids[first, first + lanes) into a vector's worth of idLanes, the lanes past `lanes` repeating
// the last id: every lane then loads a record the caller owns, and the caller masks them off.
HWY_INLINE void laneIds(const std::uint32_t* ids, std::uint32_t first, std::uint32_t lanes, std::uint32_t* idLanes) {
    const std::size_t n = hn::Lanes(DF());
    for (std::size_t l = 0; l < n; ++l) idLanes[l] = ids[first + std::min(std::uint32_t(l), lanes - 1)];
}

// shared::rayBoxIntervalRounded lane by lane. Rays with a zero component of invDir (parallel
// to a slab) are rare but for axis-aligned lights, so a vector without one takes the short
// slabs: the same values, fewer instructions.
HWY_INLINE void rayBoxIntervalRounded(const VF origin[3], const VF invDir[3], const glm::vec3& lo, const glm::vec3& hi,
                                      VF& tNear, VF& tFar) {
    const DF df;
    const VF zero = hn::Zero(df);
    VF xn, xf, yn, yf, zn, zf;
    if (hn::AllFalse(df, hn::Or(hn::Or(invDir[0] == zero, invDir[1] == zero), invDir[2] == zero))) {
        slabIntervalCrossing(origin[0], invDir[0], lo.x, hi.x, xn, xf);
        slabIntervalCrossing(origin[1], invDir[1], lo.y, hi.y, yn, yf);
        slabIntervalCrossing(origin[2], invDir[2], lo.z, hi.z, zn, zf);
    } else {
        slabInterval(origin[0], invDir[0], lo.x, hi.x, xn, xf);
        slabInterval(origin[1], invDir[1], lo.y, hi.y, yn, yf);
        slabInterval(origin[2], invDir[2], lo.z, hi.z, zn, zf);
    }
    tNear = maxLike(xn, maxLike(yn, zn));
    tFar = minLike(xf, minLike(yf, zf));
}

// shared::rayMayCrossCell lane by lane: the ray may meet the (widened) cell at some t in
// [tmin, tmax].
HWY_INLINE MF mayCrossCell(const VF origin[3], const VF invDir[3], VF tmin, VF tmax, const glm::vec3& lo,
                           const glm::vec3& hi) {
    VF tNear, tFar;
    rayBoxIntervalRounded(origin, invDir, lo, hi, tNear, tFar);
    return hn::And(hn::And(tNear <= tFar, tFar >= tmin), tNear <= tmax);
}

template <SharedRayFields kShared>
HWY_INLINE std::uint32_t partitionRays(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count,
                                       const Box& cell, std::uint32_t* scratch) {
    static_assert(sizeof(Ray) == 16 * sizeof(float) && sizeof(Hit) == 4 * sizeof(float));
    constexpr bool kSharedStart = kShared == SharedRayFields::Start;
    constexpr bool kSharedSegment = kShared == SharedRayFields::Segment;
    constexpr bool kOwnSegment = kShared == SharedRayFields::OwnSegment;
    const float* ray = reinterpret_cast<const float*>(rays);
    const float* hit = reinterpret_cast<const float*>(hits);
    const DF df;
    const DU du;
    // The fields every ray has of rays[0]'s (SharedRayFields), broadcast.
    const VF sharedOrigin[3] = {hn::Set(df, rays[0].origin.x), hn::Set(df, rays[0].origin.y),
                                hn::Set(df, rays[0].origin.z)};
    const VF sharedTmin = hn::Set(df, rays[0].tmin);
    const VF sharedBestT = hn::Set(df, rays[0].tmax);
    return stablePartition(ids, count, scratch, [&](VU, const std::uint32_t* idLanes) {
        // shared::rayMayCrossCell: origin at floats 0-2 of a Ray, tmin at 3, invDir at 8-10;
        // the best t so far is float 0 of the Hit (a second cache line per ray, which a
        // shared segment spares, and any-hit rays' own segments: tmax at float 11).
        VF start[4], invDir[4];
        if constexpr (!kSharedStart) loadQuadPerLane<0>(ray, idLanes, start);
        loadQuadPerLane<8>(ray, idLanes, invDir);
        const VF tmin = kSharedStart || kSharedSegment ? sharedTmin : start[3];
        const VF tmax = kSharedSegment ? sharedBestT : kOwnSegment ? invDir[3] : loadPerLane<4>(hit, idLanes, 0);
        return hn::RebindMask(du, mayCrossCell(kSharedStart ? sharedOrigin : start, invDir, tmin, tmax, cell.lo, cell.hi));
    });
}

std::uint32_t PartitionRays(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count,
                            const Box& cell, SharedRayFields shared, std::uint32_t* scratch) {
    switch (shared) {
        case SharedRayFields::Start: return partitionRays<SharedRayFields::Start>(rays, hits, ids, count, cell, scratch);
        case SharedRayFields::Segment:
            return partitionRays<SharedRayFields::Segment>(rays, hits, ids, count, cell, scratch);
        case SharedRayFields::OwnSegment:
            return partitionRays<SharedRayFields::OwnSegment>(rays, hits, ids, count, cell, scratch);
        case SharedRayFields::None: break;
    }
    return partitionRays<SharedRayFields::None>(rays, hits, ids, count, cell, scratch);
}

// DacrtTraversal's end of a leaf, lane by lane: a ray with a hit ends if it seeks any hit or
// if shared::hitEndsInBox holds (its t no later than the widened exit from box). The ending
// rays are swapped to the front one at a time in id order, as the scalar loop swaps them: a
// swap at position k moves only positions at or before k, so each vector's answers, taken
// before its swaps, are the ones the scalar loop reaches.
std::uint32_t EndRaysHitInBox(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count, const Box& box,
                              bool anyHit) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const float* ray = reinterpret_cast<const float*>(rays);
    const float* hit = reinterpret_cast<const float*>(hits);
    const VU miss = hn::Set(du, kMissPrim);
    const VF slabSlack = hn::Set(df, shared::kSlabSlack);
    static_assert(HWY_LANES(float) <= 16, "the ending lanes are read as 16 mask bits");
    alignas(64) std::uint32_t idLanes[64];
    std::uint32_t ended = 0;
    for (std::uint32_t k = 0; k < count; k += std::uint32_t(n)) {
        const std::uint32_t lanes = std::min(std::uint32_t(n), count - k);
        laneIds(ids, k, lanes, idLanes);
        VF best[4];
        loadQuadPerLane<0, 4>(hit, idLanes, best);  // t, prim, u, v
        MF ends = hn::And(hn::RebindMask(df, hn::BitCast(du, best[1]) != miss), hn::FirstN(df, lanes));
        if (!anyHit && !hn::AllFalse(df, ends)) {
            // shared::rayBoxInterval's far end: origin at floats 0-2 of a Ray, invDir at 8-10.
            VF start[4], invDir[4];
            loadQuadPerLane<0>(ray, idLanes, start);
            loadQuadPerLane<8>(ray, idLanes, invDir);
            VF tNear, tFar;
            rayBoxIntervalRounded(start, invDir, box.lo, box.hi, tNear, tFar);
            const VF farHigh = hn::Add(tFar, hn::Mul(hn::Abs(tFar), slabSlack));
            ends = hn::And(ends, best[0] <= farHigh);
        }
        std::uint8_t bits[8] = {};
        hn::StoreMaskBits(df, ends, bits);
        for (std::uint32_t m = std::uint32_t(bits[0]) | std::uint32_t(bits[1]) << 8; m; m &= m - 1) {
            const std::uint32_t at = k + std::uint32_t(__builtin_ctz(m));
            std::swap(ids[at], ids[ended]);
            ++ended;
        }
    }
    return ended;
}

// The coordinates b[id * kStride] of lanes' triangles: a face of the records (stride 8) or
// of a column (stride 1).
template <bool kLowSide, bool kReaching, std::size_t kStride>
HWY_INLINE std::uint32_t partitionTrianglesOnFace(const float* b, std::uint32_t* ids, std::uint32_t count, float bound,
                                                  std::uint32_t* scratch) {
    const DF df;
    const DU du;
    const VF face = hn::Set(df, bound);
    return stablePartition(ids, count, scratch, [&](VU, const std::uint32_t* idLanes) {
        const VF coordinate = loadPerLane<kStride>(b, idLanes, 0);
        const MF reaches = kLowSide ? coordinate <= face : coordinate >= face;
        // Bounds are never NaN (the loader refuses such vertices): beyond is the comparison negated.
        return hn::RebindMask(du, kReaching ? reaches : hn::Not(reaches));
    });
}

template <std::size_t kStride>
HWY_INLINE std::uint32_t partitionOnFace(const float* b, std::uint32_t* ids, std::uint32_t count, bool lowSide, float bound,
                                         std::uint32_t* scratch, FaceSide keep) {
    const bool reaching = keep == FaceSide::Reaching;
    if (lowSide)
        return reaching ? partitionTrianglesOnFace<true, true, kStride>(b, ids, count, bound, scratch)
                        : partitionTrianglesOnFace<true, false, kStride>(b, ids, count, bound, scratch);
    return reaching ? partitionTrianglesOnFace<false, true, kStride>(b, ids, count, bound, scratch)
                    : partitionTrianglesOnFace<false, false, kStride>(b, ids, count, bound, scratch);
}

std::uint32_t PartitionTrianglesOnFace(const TriangleFaces& faces, std::uint32_t* ids, std::uint32_t count, int axis,
                                       bool lowSide, float bound, std::uint32_t* scratch, FaceSide keep) {
    // lo[axis] for a new high face (lowSide), hi[axis] for a new low one.
    if (faces.columns)
        return partitionOnFace<1>(faces.columns + std::size_t(lowSide ? axis : 3 + axis) * faces.count, ids, count,
                                  lowSide, bound, scratch, keep);
    return partitionOnFace<8>(reinterpret_cast<const float*>(faces.bounds) + (lowSide ? 0 : 4) + axis, ids, count, lowSide,
                              bound, scratch, keep);
}

HWY_INLINE bool triangleHasNoArea(const LeafTriangles& batch, std::size_t j) {
    auto vertex = [&](int k) { return glm::vec3(batch.vertex[k][0][j], batch.vertex[k][1][j], batch.vertex[k][2][j]); };
    return shared::triangleHasNoArea(vertex(0), vertex(1), vertex(2));
}

// Copies the triangles' vertices into the batch's lanes.
void GatherLeafTriangles(const Triangle* triangles, const std::uint32_t* triIds, std::uint32_t count,
                         LeafTriangles& batch) {
    static_assert(sizeof(Triangle) == 12 * sizeof(float));
    static_assert(offsetof(Triangle, cullBackFace) == 3 * sizeof(float));
    const DU du;
    const std::size_t n = hn::Lanes(du);
    batch.count = count;
    // Each triangle's fields copied into its lane with a load per row and lane (loadQuadPerLane),
    // not ten gathers a vector of lanes (loadPerLane says why). Past count: the batch's first
    // triangle again, whose extra lanes the tests never read as hits (FirstN).
    const std::size_t lanes = (std::size_t(count) + n - 1) / n * n;
    // The batch's triangles are scattered over the scene's array (a large scene's exceeds the
    // caches): every one asked for before the first is copied, so that their misses overlap
    // instead of each copy waiting on its own (docs/benchmarks.md, "Prefetched leaves").
    for (std::size_t j = 0; j < count; ++j) prefetchTriangle(triangles[triIds[j]]);
    const DF df;
    const float* base = reinterpret_cast<const float*>(triangles);
    alignas(64) std::uint32_t ids[64];
    for (std::size_t j = 0; j < lanes; j += n) {
        for (std::size_t l = 0; l < n; ++l) ids[l] = triIds[j + l < count ? j + l : 0];
        // A Triangle's three 16-byte rows (v0 and cullBackFace, v1, v2), each a quad per lane
        // turned into one vector per float: the same bits, moved, not computed.
        VF rows[3][4];
        loadQuadPerLane<0, 12>(base, ids, rows[0]);
        loadQuadPerLane<4, 12>(base, ids, rows[1]);
        loadQuadPerLane<8, 12>(base, ids, rows[2]);
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) hn::Store(rows[k][c], df, &batch.vertex[k][c][j]);
        hn::Store(hn::BitCast(du, rows[0][3]), du, &batch.cullBackFace[j]);
        hn::Store(hn::LoadU(du, ids), du, &batch.prim[j]);
    }
}

// shared::intersectWatertight's projection slack for vertices a, b, c less the ray's origin:
// their largest absolute coordinate (no -0, no NaN in a maximum of absolute values, so the
// same value whichever equal operand wins) times kProjectionSlack.
HWY_INLINE VF projectionSlackOf(const VF (&a)[3], const VF (&b)[3], const VF (&c)[3]) {
    const DF df;
    const VF reach = hn::Max(hn::Max(hn::Max(hn::Abs(a[0]), hn::Abs(a[1])), hn::Max(hn::Abs(a[2]), hn::Abs(b[0]))),
                             hn::Max(hn::Max(hn::Abs(b[1]), hn::Abs(b[2])),
                                     hn::Max(hn::Max(hn::Abs(c[0]), hn::Abs(c[1])), hn::Abs(c[2]))));
    return hn::Mul(reach, hn::Set(df, shared::kProjectionSlack));
}

// shared::intersectWatertight's tests after the move to the ray's origin, lanes at a time, on
// the vertices less the origin in the ray's axes order (p[0] = a[kx], p[1] = a[ky], p[2] =
// a[kz]): the edge test first, the rest only where some lane passes it. live holds the lanes
// to test (the triangles, or the rays, there are); cull the lanes whose back faces are culled;
// slackOf() the projection slack, asked for only past the edge test. False where no lane hits;
// else live the lanes that hit, with their t, their edge values ev and ew and determinant det.
template <class SlackOf>
HWY_INLINE bool watertightInLanes(const VF (&a)[3], const VF (&b)[3], const VF (&c)[3], VF sx, VF sy, VF sz, MF cull,
                                  VF tmin, SlackOf slackOf, MF& live, VF& t, VF& ev, VF& ew, VF& det) {
    const DF df;
    const VF zero = hn::Zero(df);
    const VF ax = hn::Sub(a[0], hn::Mul(sx, a[2])), ay = hn::Sub(a[1], hn::Mul(sy, a[2]));
    const VF bx = hn::Sub(b[0], hn::Mul(sx, b[2])), by = hn::Sub(b[1], hn::Mul(sy, b[2]));
    const VF cx = hn::Sub(c[0], hn::Mul(sx, c[2])), cy = hn::Sub(c[1], hn::Mul(sy, c[2]));
    const VF eu = hn::Sub(hn::Mul(cx, by), hn::Mul(cy, bx));
    ev = hn::Sub(hn::Mul(ax, cy), hn::Mul(ay, cx));
    ew = hn::Sub(hn::Mul(bx, ay), hn::Mul(by, ax));
    const MF anyNegative = hn::Or(hn::Or(eu < zero, ev < zero), ew < zero);
    const MF anyPositive = hn::Or(hn::Or(eu > zero, ev > zero), ew > zero);
    MF m = hn::AndNot(hn::And(anyNegative, anyPositive), live);
    det = hn::Add(hn::Add(eu, ev), ew);
    m = hn::AndNot(det == zero, m);
    m = hn::AndNot(hn::And(cull, det < zero), m);  // shared::backFaceIsCulled
    // Most triangles fail the edge test: the rest of the conjunction only where one passes.
    if (hn::AllFalse(df, m)) return false;
    // Max and Min rather than maxLike and minLike here: the extremes of the projected vertices
    // are only compared, where +0 equals -0.
    const VF slack = slackOf();
    const VF negSlack = hn::Neg(slack);
    const MF outside = hn::Or(hn::Or(hn::Min(ax, hn::Min(bx, cx)) > slack, hn::Max(ax, hn::Max(bx, cx)) < negSlack),
                              hn::Or(hn::Min(ay, hn::Min(by, cy)) > slack, hn::Max(ay, hn::Max(by, cy)) < negSlack));
    m = hn::AndNot(outside, m);
    if (hn::AllFalse(df, m)) return false;
    const VF az = hn::Mul(sz, a[2]), bz = hn::Mul(sz, b[2]), cz = hn::Mul(sz, c[2]);
    const VF tScaled = hn::Add(hn::Add(hn::Mul(eu, az), hn::Mul(ev, bz)), hn::Mul(ew, cz));
    const MF front = det > zero;
    const MF behind = hn::Or(hn::And(front, tScaled <= zero), hn::AndNot(front, tScaled >= zero));
    m = hn::AndNot(behind, m);
    t = hn::Div(tScaled, det);
    live = hn::And(m, t > tmin);
    return !hn::AllFalse(df, live);
}

// What the back-face skip of intersectRay reads of a batch: each triangle's n = (v1 - v0) x
// (v2 - v0) in lanes, a bias per lane added to n's side (0 for a single-sided triangle; NaN for
// a double-sided one, which is then never skipped; +infinity for the lanes past the count, so
// that they never hold a vector's test), and the box of the batch's vertices (the padded lanes
// repeat the first triangle, so they widen nothing). None of it where no triangle is
// single-sided.
struct BatchFaces {
    alignas(64) float normal[3][kLeafBatch];
    alignas(64) float bias[kLeafBatch];
    glm::vec3 lo{}, hi{};
    bool anyCulled = false;
};

HWY_INLINE void facesOf(const LeafTriangles& batch, BatchFaces& faces) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    auto culled = hn::Zero(du);
    for (std::size_t j = 0; j < batch.count; j += n) culled = hn::Or(culled, hn::Load(du, &batch.cullBackFace[j]));
    faces.anyCulled = !hn::AllTrue(du, culled == hn::Zero(du));
    if (!faces.anyCulled) return;
    VF lo[3], hi[3];
    const VF infinity = hn::Set(df, std::numeric_limits<float>::infinity());
    const VF notANumber = hn::Set(df, std::numeric_limits<float>::quiet_NaN());
    for (int c = 0; c < 3; ++c) {
        lo[c] = infinity;
        hi[c] = hn::Neg(infinity);
    }
    for (std::size_t j = 0; j < batch.count; j += n) {
        VF v[3][3];
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) v[k][c] = hn::Load(df, &batch.vertex[k][c][j]);
        VF e1[3], e2[3];
        for (int c = 0; c < 3; ++c) {
            e1[c] = hn::Sub(v[1][c], v[0][c]);
            e2[c] = hn::Sub(v[2][c], v[0][c]);
            lo[c] = hn::Min(lo[c], hn::Min(v[0][c], hn::Min(v[1][c], v[2][c])));
            hi[c] = hn::Max(hi[c], hn::Max(v[0][c], hn::Max(v[1][c], v[2][c])));
        }
        for (int c = 0; c < 3; ++c) {
            const int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            hn::Store(hn::Sub(hn::Mul(e1[c1], e2[c2]), hn::Mul(e1[c2], e2[c1])), df, &faces.normal[c][j]);
        }
        const MF single = hn::RebindMask(df, hn::Load(du, &batch.cullBackFace[j]) != hn::Zero(du));
        const MF live = hn::FirstN(df, batch.count - j);
        hn::Store(hn::IfThenElse(live, hn::IfThenElse(single, hn::Zero(df), notANumber), infinity), df, &faces.bias[j]);
    }
    for (int c = 0; c < 3; ++c) {
        faces.lo[c] = hn::GetLane(hn::MinOfLanes(df, lo[c]));
        faces.hi[c] = hn::GetLane(hn::MaxOfLanes(df, hi[c]));
    }
}

// The back-face skip's margin for a ray from origin over faces' box (docs/correctness.md,
// "Back faces skipped in a leaf"): 2^-12 R^2 + 2^-120, R the largest coordinate of a vertex
// less the origin; infinite (nothing skipped) past R = 2^40, where the bound's products could
// overflow.
HWY_INLINE float backFaceMargin(const BatchFaces& faces, const glm::vec3& origin) {
    float reach = 0.0f;
    for (int c = 0; c < 3; ++c)
        reach = std::max(reach, std::max(std::abs(faces.lo[c] - origin[c]), std::abs(faces.hi[c] - origin[c])));
    if (!(reach <= 0x1p40f)) return std::numeric_limits<float>::infinity();
    return reach * reach * 0x1p-12f + 0x1p-120f;
}

// shared::intersectWatertight for one ray and hn::Lanes triangles at a time; the tie rule then
// runs per hit lane in scalar code. The ray's axes are template arguments, so that a[kx] and
// the like name registers: indexed by a run-time axis, the vertex vectors went through the
// stack on every batch of triangles. An any-hit ray (kAnyHit) that has a hit is done: it
// tests nothing more, and it takes the first hit lane of the first vector that has one.
//
// A vector whose single-sided triangles all show the ray their backs, by more than the rounding
// of the test's determinant can hide, is skipped before the test (docs/correctness.md, "Back
// faces skipped in a leaf"): its determinants are all negative, so the face rule rejects every
// lane. The leaves of occlusion and shadow rays, which leave a surface outwards, are mostly such
// vectors. faces: the batch's (facesOf).
template <int kx, int ky, int kz, bool kAnyHit>
HWY_INLINE Hit intersectRay(const Ray& ray, Hit best, const LeafTriangles& batch, const BatchFaces& faces) {
    if constexpr (kAnyHit)
        if (best.prim != kMissPrim) return best;
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    alignas(64) float tLane[64], uLane[64], vLane[64];
    static_assert(HWY_LANES(float) <= 16, "the hit lanes are read as 16 mask bits");
    std::uint8_t bits[8] = {};
    const VF sx = hn::Set(df, ray.shear.x), sy = hn::Set(df, ray.shear.y), sz = hn::Set(df, ray.shear.z);
    const VF origin[3] = {hn::Set(df, ray.origin.x), hn::Set(df, ray.origin.y), hn::Set(df, ray.origin.z)};
    const VF tmin = hn::Set(df, ray.tmin);
    // A bit per vector that some lane of holds the test (every vector where no triangle is
    // single-sided). A ray that every vector shows its back is done here, with no branch per
    // vector. The sheared frame's determinant is -sigma n . w, w the vector with the shear's x
    // and y on axes kx and ky and 1 on kz, sigma the sign of the permutation (kx, ky, kz): so
    // the face rule rejects where sigma n . w is positive, and `toward` is sigma w.
    std::uint64_t tested = ~std::uint64_t(0);
    if (faces.anyCulled) {
        const VF margin = hn::Set(df, backFaceMargin(faces, ray.origin));
        const float sigma = ky == (kx + 1) % 3 ? 1.0f : -1.0f;
        VF toward[3];
        toward[kx] = hn::Set(df, sigma * ray.shear.x);
        toward[ky] = hn::Set(df, sigma * ray.shear.y);
        toward[kz] = hn::Set(df, sigma);
        tested = 0;
        for (std::size_t j = 0; j < batch.count; j += n) {
            const VF side = hn::Add(hn::Add(hn::Add(hn::Mul(hn::Load(df, &faces.normal[0][j]), toward[0]),
                                                    hn::Mul(hn::Load(df, &faces.normal[1][j]), toward[1])),
                                            hn::Mul(hn::Load(df, &faces.normal[2][j]), toward[2])),
                                    hn::Load(df, &faces.bias[j]));
            tested |= std::uint64_t(!hn::AllTrue(df, side > margin)) << (j / n);
        }
        if (tested == 0) return best;
    }
    for (std::size_t j = 0; j < batch.count; j += n) {
        if ((tested >> (j / n) & 1) == 0) continue;
        const MF cull = hn::RebindMask(df, hn::Load(du, &batch.cullBackFace[j]) != hn::Zero(du));
        VF a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = hn::Sub(hn::Load(df, &batch.vertex[0][k][j]), origin[k]);
            b[k] = hn::Sub(hn::Load(df, &batch.vertex[1][k][j]), origin[k]);
            c[k] = hn::Sub(hn::Load(df, &batch.vertex[2][k][j]), origin[k]);
        }
        const VF pa[3] = {a[kx], a[ky], a[kz]}, pb[3] = {b[kx], b[ky], b[kz]}, pc[3] = {c[kx], c[ky], c[kz]};
        auto slackOf = [&] { return projectionSlackOf(a, b, c); };
        MF m = hn::FirstN(df, batch.count - j);
        VF t, ev, ew, det;
        if (!watertightInLanes(pa, pb, pc, sx, sy, sz, cull, tmin, slackOf, m, t, ev, ew, det)) continue;
        hn::Store(t, df, tLane);
        hn::Store(hn::Div(ev, det), df, uLane);
        hn::Store(hn::Div(ew, det), df, vLane);
        hn::StoreMaskBits(df, m, bits);
        for (std::uint32_t lanes = std::uint32_t(bits[0]) | std::uint32_t(bits[1]) << 8; lanes; lanes &= lanes - 1) {
            const std::size_t l = std::size_t(__builtin_ctz(lanes));
            // The no-area rule, last of the conjunction, only where the rest says hit.
            if (triangleHasNoArea(batch, j + l)) continue;
            const std::uint32_t prim = batch.prim[j + l];
            if (!shared::hitPrecedes(tLane[l], prim, best.t, best.prim)) continue;
            best = Hit{tLane[l], prim, uLane[l], vLane[l]};
            if constexpr (kAnyHit) return best;
        }
    }
    return best;
}

// The axes as makeRay packs them (kx | ky << 2 | kz << 4): kz the largest component, kx and
// ky the next two in cyclic order, swapped where the direction along kz is negative.
constexpr std::uint32_t packedAxes(int kx, int ky, int kz) { return std::uint32_t(kx | ky << 2 | kz << 4); }

template <bool kAnyHit>
HWY_INLINE void intersectRays(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                              const LeafTriangles& batch, const BatchFaces& faces) {
    // A few rays ahead asked for: a leaf's rays are scattered over the pass's arrays.
    constexpr std::uint32_t kRaysAhead = 4;
    for (std::uint32_t r = 0; r < rayCount; ++r) {
        const std::uint32_t rayId = rayIds[r];
        if (r + kRaysAhead < rayCount) {
            __builtin_prefetch(rays + rayIds[r + kRaysAhead]);
            __builtin_prefetch(hits + rayIds[r + kRaysAhead]);
        }
        const Ray& ray = rays[rayId];
        const Hit best = hits[rayId];
        switch (ray.axes) {
            case packedAxes(1, 2, 0): hits[rayId] = intersectRay<1, 2, 0, kAnyHit>(ray, best, batch, faces); break;
            case packedAxes(2, 1, 0): hits[rayId] = intersectRay<2, 1, 0, kAnyHit>(ray, best, batch, faces); break;
            case packedAxes(2, 0, 1): hits[rayId] = intersectRay<2, 0, 1, kAnyHit>(ray, best, batch, faces); break;
            case packedAxes(0, 2, 1): hits[rayId] = intersectRay<0, 2, 1, kAnyHit>(ray, best, batch, faces); break;
            case packedAxes(0, 1, 2): hits[rayId] = intersectRay<0, 1, 2, kAnyHit>(ray, best, batch, faces); break;
            case packedAxes(1, 0, 2): hits[rayId] = intersectRay<1, 0, 2, kAnyHit>(ray, best, batch, faces); break;
            default: HWY_ABORT("ray axes %u: makeRay and segmentRay make only six", ray.axes);
        }
    }
}

void IntersectBatch(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                    const LeafTriangles& batch, bool anyHit) {
    BatchFaces faces;
    facesOf(batch, faces);
    if (anyHit)
        intersectRays<true>(rays, hits, rayIds, rayCount, batch, faces);
    else
        intersectRays<false>(rays, hits, rayIds, rayCount, batch, faces);
}

// The batch's triangle bounds, widened, lanes at a time: min and max of exact vertices, then
// one rounding of the widening.
struct WidenedBounds {
    alignas(64) float lo[3][kLeafBatch];
    alignas(64) float hi[3][kLeafBatch];
};

HWY_INLINE void widenedBoundsOf(const LeafTriangles& batch, float widening, WidenedBounds& b) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    const VF w = hn::Set(df, widening);
    for (std::size_t j = 0; j < batch.count; j += n)
        for (int c = 0; c < 3; ++c) {
            const VF v0 = hn::Load(df, &batch.vertex[0][c][j]), v1 = hn::Load(df, &batch.vertex[1][c][j]),
                     v2 = hn::Load(df, &batch.vertex[2][c][j]);
            hn::Store(hn::Sub(hn::Min(hn::Min(v0, v1), v2), w), df, &b.lo[c][j]);
            hn::Store(hn::Add(hn::Max(hn::Max(v0, v1), v2), w), df, &b.hi[c][j]);
        }
}

// The lanes of batch whose widened bounds the group may cross (packetMayCrossCell,
// ray_packet.cpp: the same products, minima and maxima lane by lane), in order, into kept.
// Returns how many. Each vector of lane numbers is stored whole at the count so far, which is
// at most its own first lane j, so no store passes lane j + n <= kLeafBatch.
HWY_INLINE std::uint32_t narrowToGroup(const LeafTriangles& batch, const WidenedBounds& b, const RayPacket& group,
                                       const glm::vec3& origin, float tmin, std::uint32_t* kept) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    std::uint32_t count = 0;
    for (std::size_t j = 0; j < batch.count; j += n) {
        VF tNear = hn::Set(df, -kNoHitT), tFar = hn::Set(df, kNoHitT);
        for (int a = 0; a < 3; ++a) {
            if ((group.unboundedAxes >> a) & 1u) continue;
            const VF o = hn::Set(df, origin[a]), lo = hn::Set(df, group.invLo[a]), hi = hn::Set(df, group.invHi[a]);
            const VF d0 = hn::Sub(hn::Load(df, &b.lo[a][j]), o), d1 = hn::Sub(hn::Load(df, &b.hi[a][j]), o);
            const VF q0 = hn::Mul(d0, lo), q1 = hn::Mul(d0, hi), q2 = hn::Mul(d1, lo), q3 = hn::Mul(d1, hi);
            tNear = hn::Max(tNear, hn::Min(hn::Min(q0, q1), hn::Min(q2, q3)));
            tFar = hn::Min(tFar, hn::Max(hn::Max(q0, q1), hn::Max(q2, q3)));
        }
        const MF may = hn::And(hn::And(tNear <= tFar, tFar >= hn::Set(df, tmin)), hn::FirstN(df, batch.count - j));
        if (hn::AllFalse(df, may)) continue;
        const VU lanes = hn::Add(hn::Iota(du, 0), hn::Set(du, std::uint32_t(j)));
        hn::StoreU(compressIds(lanes, hn::RebindMask(du, may)), du, kept + count);
        count += std::uint32_t(hn::CountTrue(df, may));
    }
    return count;
}

// The batch's vertices less the rays' shared origin, and each triangle's projection slack:
// the parts of the watertight test that do not depend on the ray's direction, computed once
// for every group, with the same operations intersectRay applies per ray.
struct BatchFromOrigin {
    alignas(64) float vertex[3][3][kLeafBatch];
    alignas(64) float slack[kLeafBatch];
};

HWY_INLINE void batchFromOrigin(const LeafTriangles& batch, const glm::vec3& origin, BatchFromOrigin& from) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    const VF o[3] = {hn::Set(df, origin.x), hn::Set(df, origin.y), hn::Set(df, origin.z)};
    for (std::size_t j = 0; j < batch.count; j += n) {
        VF a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = hn::Sub(hn::Load(df, &batch.vertex[0][k][j]), o[k]);
            b[k] = hn::Sub(hn::Load(df, &batch.vertex[1][k][j]), o[k]);
            c[k] = hn::Sub(hn::Load(df, &batch.vertex[2][k][j]), o[k]);
            hn::Store(a[k], df, &from.vertex[0][k][j]);
            hn::Store(b[k], df, &from.vertex[1][k][j]);
            hn::Store(c[k], df, &from.vertex[2][k][j]);
        }
        hn::Store(projectionSlackOf(a, b, c), df, &from.slack[j]);
    }
}

// A lane per ray: each ray's best hit so far, as the tie rule compares it.
struct BestInLanes {
    VF t, u, v;
    VU prim;
};

// intersectRay with the rays in lanes and the kept triangles one at a time: a group's rays
// share their origin, so a triangle's vertices less the origin and its slack are one value
// for every lane, and only the ray's axes, shear and best hit differ from lane to lane. Each
// lane computes what intersectRay computes for its ray, operation for operation, picking its
// ray's kx, ky and kz coordinates by selection (is0[k] and is1[k]: coordinate k is 0, 1, else
// 2), which moves bits without rounding. Where a group keeps few of a batch's triangles (most
// leaves), a lane per ray does a vector of work per triangle kept, where a lane per triangle
// did a vector per ray.
HWY_INLINE void testKeptTriangles(const LeafTriangles& batch, const BatchFromOrigin& from, const std::uint32_t* kept,
                                  std::uint32_t keptCount, const VF (&shear)[4], VF tmin, MF valid, const MF (&is0)[3],
                                  const MF (&is1)[3], BestInLanes& best) {
    const DF df;
    const DU du;
    const DI di;
    const VF sx = shear[0], sy = shear[1], sz = shear[2];
    const VU flip = hn::Set(du, 0x80000000u);
    const MF none = hn::FirstN(df, 0);
    for (std::uint32_t i = 0; i < keptCount; ++i) {
        const std::uint32_t j = kept[i];
        auto pick = [&](int vertex, int k) {
            const float* coordinate = &from.vertex[vertex][0][j];  // coordinate c at [c * kLeafBatch]
            return hn::IfThenElse(is0[k], hn::Set(df, coordinate[0]),
                                  hn::IfThenElse(is1[k], hn::Set(df, coordinate[kLeafBatch]),
                                                 hn::Set(df, coordinate[2 * kLeafBatch])));
        };
        const VF a[3] = {pick(0, 0), pick(0, 1), pick(0, 2)};
        const VF b[3] = {pick(1, 0), pick(1, 1), pick(1, 2)};
        const VF c[3] = {pick(2, 0), pick(2, 1), pick(2, 2)};
        MF m = valid;
        VF t, ev, ew, det;
        if (!watertightInLanes(a, b, c, sx, sy, sz, batch.cullBackFace[j] != 0u ? valid : none, tmin,
                               [&] { return hn::Set(df, from.slack[j]); }, m, t, ev, ew, det))
            continue;
        // The no-area rule, last of the conjunction, only where the rest says hit.
        if (triangleHasNoArea(batch, j)) continue;
        // shared::hitPrecedes, lane by lane, the ids compared as unsigned (kMissPrim the largest).
        const VU prim = hn::Set(du, batch.prim[j]);
        const auto idBefore = hn::BitCast(di, hn::Xor(prim, flip)) < hn::BitCast(di, hn::Xor(best.prim, flip));
        const MF precedes = hn::Or(t < best.t, hn::And(t == best.t, hn::RebindMask(df, idBefore)));
        const MF update = hn::And(m, precedes);
        best.t = hn::IfThenElse(update, t, best.t);
        best.u = hn::IfThenElse(update, hn::Div(ev, det), best.u);
        best.v = hn::IfThenElse(update, hn::Div(ew, det), best.v);
        best.prim = hn::IfThenElse(hn::RebindMask(du, update), prim, best.prim);
    }
}

// The kept triangles against the group's rays, a vector of rays at a time.
HWY_INLINE void intersectGroupInLanes(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                                      const LeafTriangles& batch, const BatchFromOrigin& from,
                                      const std::uint32_t* kept, std::uint32_t keptCount, float rayTmin) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const float* rayFloats = reinterpret_cast<const float*>(rays);
    const float* hitFloats = reinterpret_cast<const float*>(hits);
    const VF tmin = hn::Set(df, rayTmin);
    const VU three = hn::Set(du, 3u);
    alignas(64) std::uint32_t ids[64];
    alignas(64) float bestLanes[4][64];
    for (std::uint32_t r = 0; r < rayCount; r += std::uint32_t(n)) {
        const std::uint32_t lanes = std::min(std::uint32_t(n), rayCount - r);
        laneIds(rayIds, r, lanes, ids);
        // Floats 4-7 of a Ray: the direction and the packed axes; 12-14 the shear.
        VF dirAndAxes[4], shear[4], hit[4];
        loadQuadPerLane<4>(rayFloats, ids, dirAndAxes);
        loadQuadPerLane<12>(rayFloats, ids, shear);
        loadQuadPerLane<0, 4>(hitFloats, ids, hit);  // t, prim, u, v
        BestInLanes best{hit[0], hit[2], hit[3], hn::BitCast(du, hit[1])};
        const MF valid = hn::FirstN(df, lanes);
        const VU axes = hn::BitCast(du, dirAndAxes[3]);
        // Lane masks choosing coordinate 0, 1 or else 2 for kx, ky and kz.
        MF is0[3], is1[3];
        for (int k = 0; k < 3; ++k) {
            const VU axis = hn::And(hn::ShiftRightSame(axes, 2 * k), three);
            is0[k] = hn::RebindMask(df, axis == hn::Zero(du));
            is1[k] = hn::RebindMask(df, axis == hn::Set(du, 1u));
        }
        testKeptTriangles(batch, from, kept, keptCount, shear, tmin, valid, is0, is1, best);
        hn::Store(best.t, df, bestLanes[0]);
        hn::Store(hn::BitCast(df, best.prim), df, bestLanes[1]);
        hn::Store(best.u, df, bestLanes[2]);
        hn::Store(best.v, df, bestLanes[3]);
        for (std::uint32_t l = 0; l < lanes; ++l) {
            Hit& h = hits[ids[l]];
            h.t = bestLanes[0][l];
            std::memcpy(&h.prim, &bestLanes[1][l], sizeof(h.prim));
            h.u = bestLanes[2][l];
            h.v = bestLanes[3][l];
        }
    }
}

// startPacketBounds and addToPacketBounds over rays[rayIds[0, count)], lanes at a time: on the
// axes left bounded every lane is finite and nonzero, so the lanes' minimum and maximum are
// the scalar fold's.
HWY_INLINE RayPacket boundsOfGroup(const Ray* rays, const std::uint32_t* rayIds, std::uint32_t count) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    const float* base = reinterpret_cast<const float*>(rays);
    const VF zero = hn::Zero(df), infinity = hn::Set(df, std::numeric_limits<float>::infinity());
    VF lo[3], hi[3];
    MF unbounded[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = hn::Set(df, kNoHitT);
        hi[a] = hn::Set(df, -kNoHitT);
        unbounded[a] = hn::FirstN(df, 0);
    }
    alignas(64) std::uint32_t ids[64];
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        const std::uint32_t lanes = std::min(std::uint32_t(n), count - i);
        laneIds(rayIds, i, lanes, ids);
        VF invDir[4];
        loadQuadPerLane<8>(base, ids, invDir);  // floats 8-10 of a Ray
        for (int a = 0; a < 3; ++a) {
            lo[a] = hn::Min(lo[a], invDir[a]);
            hi[a] = hn::Max(hi[a], invDir[a]);
            unbounded[a] = hn::Or(unbounded[a], hn::Or(invDir[a] == zero, hn::Not(hn::Abs(invDir[a]) < infinity)));
        }
    }
    RayPacket p;
    for (int a = 0; a < 3; ++a) {
        p.invLo[a] = hn::GetLane(hn::MinOfLanes(df, lo[a]));
        p.invHi[a] = hn::GetLane(hn::MaxOfLanes(df, hi[a]));
        if (!hn::AllFalse(df, unbounded[a])) p.unboundedAxes |= 1u << a;
    }
    return p;
}

RayPacket BoundsOfRays(const Ray* rays, const std::uint32_t* rayIds, std::uint32_t count) {
    return boundsOfGroup(rays, rayIds, count);
}

std::uint64_t IntersectBatchInGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                                     const LeafTriangles& batch, float widening) {
    WidenedBounds bounds;
    widenedBoundsOf(batch, widening, bounds);
    const glm::vec3 origin = rays[0].origin;  // every ray's (SharedRayFields::Start)
    const float tmin = rays[0].tmin;
    BatchFromOrigin from;
    batchFromOrigin(batch, origin, from);
    alignas(64) std::uint32_t kept[kLeafBatch];
    std::uint64_t skipped = 0;
    for (std::uint32_t g = 0; g < rayCount; g += kLeafGroupRays) {
        const std::uint32_t groupRays = std::min(kLeafGroupRays, rayCount - g);
        // The next group's rays and hits asked for: a large leaf's rays are scattered over
        // more than the caches hold, and each group waited on its own misses.
        for (std::uint32_t k = g + kLeafGroupRays; k < std::min(g + 2 * kLeafGroupRays, rayCount); ++k) {
            __builtin_prefetch(rays + rayIds[k]);
            __builtin_prefetch(hits + rayIds[k]);
        }
        const RayPacket group = boundsOfGroup(rays, rayIds + g, groupRays);
        const std::uint32_t keptCount = narrowToGroup(batch, bounds, group, origin, tmin, kept);
        skipped += std::uint64_t(groupRays) * (batch.count - keptCount);
        if (keptCount == 0) continue;
        intersectGroupInLanes(rays, hits, rayIds + g, groupRays, batch, from, kept, keptCount, tmin);
    }
    return skipped;
}

// How many groups of a leaf's rays try the narrowing before it is kept or dropped.
constexpr std::uint32_t kTrialGroups = 2;

// The box of the group's segments from their origins (the watertight test reports no hit at
// t < 0, whatever tmin is) to their best t so far (a later hit must precede it, so it lies
// before that t): the smallest and largest of o and o + t d over the group, lanes at a time.
// Never not a number: the rays' fields are finite and t at most kNoHitT (an infinite tmax is
// stored as kNoHitT), so o + t d overflows at worst to an infinity, which narrows nothing.
HWY_INLINE void boxOfSegments(const Ray* rays, const Hit* hits, const std::uint32_t* rayIds, std::uint32_t count,
                              glm::vec3& lo, glm::vec3& hi) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    const float* rayFloats = reinterpret_cast<const float*>(rays);
    const float* hitFloats = reinterpret_cast<const float*>(hits);
    alignas(64) std::uint32_t ids[64];
    VF boxLo[3], boxHi[3];
    for (int a = 0; a < 3; ++a) {
        boxLo[a] = hn::Set(df, kNoHitT);
        boxHi[a] = hn::Set(df, -kNoHitT);
    }
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        laneIds(rayIds, i, std::min(std::uint32_t(n), count - i), ids);
        VF origin[4], dir[4];
        loadQuadPerLane<0>(rayFloats, ids, origin);
        loadQuadPerLane<4>(rayFloats, ids, dir);
        const VF t = loadPerLane<4>(hitFloats, ids, 0);
        for (int a = 0; a < 3; ++a) {
            const VF end = hn::Add(origin[a], hn::Mul(t, dir[a]));
            boxLo[a] = hn::Min(boxLo[a], hn::Min(origin[a], end));
            boxHi[a] = hn::Max(boxHi[a], hn::Max(origin[a], end));
        }
    }
    for (int a = 0; a < 3; ++a) {
        lo[a] = hn::GetLane(hn::MinOfLanes(df, boxLo[a]));
        hi[a] = hn::GetLane(hn::MaxOfLanes(df, boxHi[a]));
    }
}

// The triangles of batch whose widened bounds overlap the box, in order, into narrowed (each
// field's vector compressed and stored whole at the count so far, which is at most its own
// first lane j, so no store passes lane j + n <= kLeafBatch), where that leaves fewer vectors
// of them to test than the batch has. Returns the batch, or narrowed.
HWY_INLINE const LeafTriangles& narrowToBox(const LeafTriangles& batch, const WidenedBounds& b, const glm::vec3& lo,
                                            const glm::vec3& hi, LeafTriangles& narrowed) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    MF overlaps[kLeafBatch];
    std::uint32_t kept = 0;
    for (std::size_t j = 0; j < batch.count; j += n) {
        MF overlap = hn::FirstN(df, batch.count - j);
        for (int a = 0; a < 3; ++a)
            overlap = hn::And(overlap, hn::And(hn::Load(df, &b.lo[a][j]) <= hn::Set(df, hi[a]),
                                               hn::Load(df, &b.hi[a][j]) >= hn::Set(df, lo[a])));
        overlaps[j / n] = overlap;
        kept += std::uint32_t(hn::CountTrue(df, overlap));
    }
    if ((kept + n - 1) / n == (batch.count + n - 1) / n) return batch;
    std::uint32_t count = 0;
    for (std::size_t j = 0; j < batch.count; j += n) {
        const MF overlap = overlaps[j / n];
        if (hn::AllFalse(df, overlap)) continue;
        const auto keep = hn::RebindMask(du, overlap);
        // Every field as 32-bit lanes: the floats' bits move unchanged.
        auto compress = [&](const void* from, void* to) {
            const VU v = hn::Load(du, static_cast<const std::uint32_t*>(from) + j);
            hn::StoreU(compressIds(v, keep), du, static_cast<std::uint32_t*>(to) + count);
        };
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) compress(batch.vertex[k][c], narrowed.vertex[k][c]);
        compress(batch.prim, narrowed.prim);
        compress(batch.cullBackFace, narrowed.cullBackFace);
        count += std::uint32_t(hn::CountTrue(df, overlap));
    }
    // The last vector's lanes past the count repeat the first kept triangle, as
    // gatherLeafTriangles pads a batch: never read as hits, and no stale values in them.
    for (std::size_t l = count; count > 0 && l < (count + n - 1) / n * n; ++l) {
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) narrowed.vertex[k][c][l] = narrowed.vertex[k][c][0];
        narrowed.prim[l] = narrowed.prim[0];
        narrowed.cullBackFace[l] = narrowed.cullBackFace[0];
    }
    narrowed.count = count;
    return narrowed;
}

// intersectBatch in groups of kLeafGroupRays consecutive ids, each testing only the triangles
// whose bounds, widened by `widening`, overlap the box of its segments (boxOfSegments). A group
// whose box holds the leaf's cell (every triangle of the leaf has bounds overlapping the cell,
// so they overlap the box too, and the narrowing would keep them all) tests them all
// without narrowing. A leaf whose first groups save less than half a vector of triangles per
// ray (small triangles, segments as long as the leaf: the Bunny's and the Dragon's occlusion
// rays) gains less than the boxes cost: its other rays test every triangle.
template <bool kAnyHit>
HWY_INLINE std::uint64_t intersectSegmentGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds,
                                                std::uint32_t rayCount, const LeafTriangles& batch, const Box& cell,
                                                float widening) {
    const std::size_t n = hn::Lanes(DF());
    auto vectors = [&](std::uint32_t triangles) { return (triangles + n - 1) / n; };
    WidenedBounds bounds;
    bool haveBounds = false;
    LeafTriangles narrowed;
    // The whole batch's faces once for every group that tests it; a narrowed batch's its own.
    BatchFaces batchFaces, narrowedFaces;
    bool haveBatchFaces = false;
    auto wholeBatch = [&]() -> const BatchFaces& {
        if (!haveBatchFaces) facesOf(batch, batchFaces);
        haveBatchFaces = true;
        return batchFaces;
    };
    std::uint64_t skipped = 0, vectorsSaved = 0;
    std::uint32_t g = 0;
    for (; g < rayCount; g += kLeafGroupRays) {
        if (g == kTrialGroups * kLeafGroupRays && vectorsSaved * 2 < g) break;
        const std::uint32_t groupRays = std::min(kLeafGroupRays, rayCount - g);
        glm::vec3 lo, hi;
        boxOfSegments(rays, hits, rayIds + g, groupRays, lo, hi);
        if (lo.x <= cell.lo.x && lo.y <= cell.lo.y && lo.z <= cell.lo.z && hi.x >= cell.hi.x &&
            hi.y >= cell.hi.y && hi.z >= cell.hi.z) {
            intersectRays<kAnyHit>(rays, hits, rayIds + g, groupRays, batch, wholeBatch());
            continue;
        }
        if (!haveBounds) {
            widenedBoundsOf(batch, widening, bounds);
            haveBounds = true;
        }
        const LeafTriangles& kept = narrowToBox(batch, bounds, lo, hi, narrowed);
        skipped += std::uint64_t(groupRays) * (batch.count - kept.count);
        vectorsSaved += std::uint64_t(groupRays) * (vectors(batch.count) - vectors(kept.count));
        if (kept.count == 0) continue;
        if (&kept == &batch) {
            intersectRays<kAnyHit>(rays, hits, rayIds + g, groupRays, batch, wholeBatch());
            continue;
        }
        facesOf(kept, narrowedFaces);
        intersectRays<kAnyHit>(rays, hits, rayIds + g, groupRays, kept, narrowedFaces);
    }
    if (g < rayCount) intersectRays<kAnyHit>(rays, hits, rayIds + g, rayCount - g, batch, wholeBatch());
    return skipped;
}

// A batch of one vector of triangles has none to save, and a leaf with fewer rays than twice
// the trial's would spend most of them on it: both test every triangle.
std::uint64_t IntersectBatchInSegmentGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds,
                                            std::uint32_t rayCount, const LeafTriangles& batch, const Box& cell,
                                            float widening, bool anyHit) {
    if (batch.count <= hn::Lanes(DF()) || rayCount < 2 * kTrialGroups * kLeafGroupRays) {
        IntersectBatch(rays, hits, rayIds, rayCount, batch, anyHit);
        return 0;
    }
    return anyHit ? intersectSegmentGroups<true>(rays, hits, rayIds, rayCount, batch, cell, widening)
                  : intersectSegmentGroups<false>(rays, hits, rayIds, rayCount, batch, cell, widening);
}

// firstRegionOfRay lanes at a time: each lane's walk start, then every region's test in
// ascending order, a lane moving up keeping the first region at or after its start that its
// ray crosses, a lane moving down the last one at or before it. The walk's clamp of its start
// and its starts for origins outside the box are left out: with every region tested they
// change no answer (a start of -1 or count selects as 0 or count - 1 does, and an origin below
// boundary[0] or above boundary[count] already gets slab 0 or count - 1). So is the walk's
// first test, of the scene box: a region's widened box lies inside the widened scene box, bit
// for bit (the same bounds but on the axis, where its boundaries do), and the lane test is
// monotone in the box, so a lane that misses the scene box crosses no region either and keeps
// kNoRegion.
void FirstRegions(const Ray* rays, std::size_t count, const RegionSlabs& s, std::uint32_t* region) {
    const DF df;
    const DI di;
    const hn::RebindToUnsigned<DI> du;
    const std::size_t n = hn::Lanes(df);
    const float* base = reinterpret_cast<const float*>(rays);
    const VF noHit = hn::Set(df, kNoHitT);
    const auto none = hn::Set(di, std::int32_t(kNoRegion));
    alignas(64) std::uint32_t ids[64], tail[64];
    for (std::size_t i = 0; i < count; i += n) {
        const std::size_t lanes = std::min(n, count - i);
        for (std::size_t l = 0; l < n; ++l) ids[l] = std::uint32_t(i + std::min(l, lanes - 1));
        // Floats 0-3 of a Ray: origin and tmin; 4-6 the direction; 8-10 its reciprocals.
        VF originAndTmin[4], dir[4], invDir[4];
        loadQuadPerLane<0>(base, ids, originAndTmin);
        loadQuadPerLane<4>(base, ids, dir);
        loadQuadPerLane<8>(base, ids, invDir);
        const VF tmin = originAndTmin[3];
        const VF origin = originAndTmin[s.axis], d = dir[s.axis];
        const auto down = hn::RebindMask(di, d < hn::Zero(df));
        // slabOf (the boundaries 1 .. count - 1 at or below the origin), then one slab behind.
        auto slab = hn::Zero(di);
        for (std::uint32_t k = 1; k < s.count; ++k)
            slab = hn::Sub(slab, hn::VecFromMask(di, hn::RebindMask(di, hn::Set(df, s.boundary[k]) <= origin)));
        const auto walk = hn::IfThenElse(down, hn::Add(slab, hn::Set(di, 1)), hn::Sub(slab, hn::Set(di, 1)));
        auto found = none;
        for (std::uint32_t k = 0; k < s.count; ++k) {
            const auto vk = hn::Set(di, std::int32_t(k));
            const auto crossed =
                hn::RebindMask(di, mayCrossCell(originAndTmin, invDir, tmin, noHit, s.wideLo[k], s.wideHi[k]));
            const auto keepMovingUp = hn::AndNot(down, hn::AndNot(vk < walk, found == none));
            const auto keepMovingDown = hn::AndNot(vk > walk, down);
            found = hn::IfThenElse(hn::And(crossed, hn::Or(keepMovingUp, keepMovingDown)), vk, found);
        }
        if (lanes == n) {
            hn::StoreU(hn::BitCast(du, found), du, region + i);
        } else {
            hn::Store(hn::BitCast(du, found), du, tail);
            std::copy(tail, tail + lanes, region + i);
        }
    }
}

// facesAwayFrom in float32 with a bound on its rounding (docs/correctness.md, "Skips"):
// side = ((v1 - v0) x (v2 - v0)) . (v0 - o) is within 10 u |e1|_1 |e2|_1 |a|_1 of the float64
// value, taken as 32 u; q > 480 u L + 200 u^2 R is certified with a factor 1.001 for the
// roundings of q, the square roots and the bound.
// Lanes whose lengths fall below 1e-10 (where float32 products could underflow) stay undecided.
void ClassifyFacing(const Triangle* triangles, std::uint32_t count, const glm::vec3& origin, std::uint8_t* verdict) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const float* tri = reinterpret_cast<const float*>(triangles);
    const VF zero = hn::Zero(df);
    const VF o[3] = {hn::Set(df, origin.x), hn::Set(df, origin.y), hn::Set(df, origin.z)};
    constexpr float u = 0x1p-24f;
    const VF errorScale = hn::Set(df, 32.0f * u), tiny = hn::Set(df, 1e-10f), margin = hn::Set(df, 1.001f);
    const VF perEdge = hn::Set(df, 480.0f * u), perReach = hn::Set(df, 200.0f * u * u);
    // Each lane's triangle by 16-byte quarters (v0 and cullBackFace, v1 and padding, v2 and
    // padding), transposed in blocks: gathers are the slower way here (AMD Zen 5: this kernel
    // ran 1.5x faster on SSE4's emulated gathers than on AVX-512's), and a copy float by float
    // into lanes took more instructions than the tests.
    alignas(64) std::uint32_t ids[64];
    for (std::uint32_t j = 0; j < count; j += std::uint32_t(n)) {
        const std::uint32_t here = std::min<std::uint32_t>(std::uint32_t(n), count - j);
        for (std::uint32_t l = 0; l < n; ++l) ids[l] = j + std::min(l, here - 1);
        VF quarters[3][4];
        loadQuadPerLane<0, 12>(tri, ids, quarters[0]);
        loadQuadPerLane<4, 12>(tri, ids, quarters[1]);
        loadQuadPerLane<8, 12>(tri, ids, quarters[2]);
        const VF(&v)[3][4] = quarters;  // v[k][0..2]: vertex k's x, y, z
        const auto single = hn::RebindMask(df, hn::BitCast(du, quarters[0][3]) != hn::Zero(du));
        VF a[3], b[3], c[3], e1[3], e2[3], e3[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = hn::Sub(v[0][k], o[k]);
            b[k] = hn::Sub(v[1][k], o[k]);
            c[k] = hn::Sub(v[2][k], o[k]);
            e1[k] = hn::Sub(v[1][k], v[0][k]);
            e2[k] = hn::Sub(v[2][k], v[0][k]);
            e3[k] = hn::Sub(v[2][k], v[1][k]);
        }
        const VF nx = hn::Sub(hn::Mul(e1[1], e2[2]), hn::Mul(e1[2], e2[1]));
        const VF ny = hn::Sub(hn::Mul(e1[2], e2[0]), hn::Mul(e1[0], e2[2]));
        const VF nz = hn::Sub(hn::Mul(e1[0], e2[1]), hn::Mul(e1[1], e2[0]));
        const VF side = hn::Add(hn::Add(hn::Mul(nx, a[0]), hn::Mul(ny, a[1])), hn::Mul(nz, a[2]));
        auto norm1 = [](const VF (&x)[3]) { return hn::Add(hn::Add(hn::Abs(x[0]), hn::Abs(x[1])), hn::Abs(x[2])); };
        auto dot = [](const VF (&x)[3]) { return hn::Add(hn::Add(hn::Mul(x[0], x[0]), hn::Mul(x[1], x[1])), hn::Mul(x[2], x[2])); };
        const VF n1 = norm1(e1), n2 = norm1(e2), na = norm1(a);
        const VF error = hn::Mul(errorScale, hn::Mul(hn::Mul(n1, n2), na));
        const MF inRange = hn::And(hn::And(n1 >= tiny, n2 >= tiny), na >= tiny);
        const VF r2 = hn::Max(hn::Max(dot(a), dot(b)), dot(c));
        const VF l2 = hn::Max(hn::Max(dot(e1), dot(e2)), dot(e3));
        const MF keep = hn::Or(hn::Not(single), hn::And(inRange, hn::Add(side, error) < zero));
        const VF low = hn::Sub(side, error);
        const VF q = hn::Div(low, r2);
        const VF bound = hn::Mul(margin, hn::Add(hn::Mul(perEdge, hn::Sqrt(l2)), hn::Mul(perReach, hn::Sqrt(r2))));
        const MF drop = hn::AndNot(hn::Not(single), hn::And(inRange, hn::And(low > zero, q > bound)));
        alignas(64) std::uint8_t keepBits[8] = {}, dropBits[8] = {};
        hn::StoreMaskBits(df, keep, keepBits);
        hn::StoreMaskBits(df, drop, dropBits);
        const std::uint32_t keepMask = std::uint32_t(keepBits[0]) | std::uint32_t(keepBits[1]) << 8;
        const std::uint32_t dropMask = std::uint32_t(dropBits[0]) | std::uint32_t(dropBits[1]) << 8;
        for (std::uint32_t l = 0; l < here; ++l)
            verdict[j + l] = (keepMask >> l & 1u) ? kKeep : (dropMask >> l & 1u) ? kDrop : kUndecided;
    }
}

// BandEdges::bandsOf (image_bands.hpp) lane by lane: the same float operations on each lane's
// bounds in the same order. Max and Min where bandsOf takes glm::max and glm::min: on finite
// bounds (a frame's are: the scene is checked for NaN and Inf on load) they differ at most in a
// zero's sign, which changes no sum's comparison with the slack.
void BandsOfBounds(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, const glm::vec3& apex,
                   const glm::vec3* up, std::uint32_t edges, std::uint32_t* first, std::uint32_t* last) {
    const DF df;
    const DU du;
    const std::size_t n = hn::Lanes(df);
    const float* b = reinterpret_cast<const float*>(bounds);
    const VF apexLanes[3] = {hn::Set(df, apex.x), hn::Set(df, apex.y), hn::Set(df, apex.z)};
    const VF slackScale = hn::Set(df, 0x1p-11f);
    alignas(64) std::uint32_t idLanes[64], firstLanes[64], lastLanes[64];
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        const std::uint32_t lanes = std::min(std::uint32_t(n), count - i);
        for (std::size_t l = 0; l < n; ++l) {
            const std::uint32_t k = i + std::min(std::uint32_t(l), lanes - 1);
            idLanes[l] = ids ? ids[k] : k;
        }
        // The bounds four vectors ahead asked for: through a list of ids the loads skip about
        // half the array, which the hardware's prefetch does not follow.
        if (ids)
            for (std::uint32_t k = i + 4 * std::uint32_t(n); k < std::min(count, i + 5 * std::uint32_t(n)); ++k)
                __builtin_prefetch(bounds + ids[k]);
        // A Bounds is 8 floats: lo and a pad, hi and a pad.
        VF loFields[4], hiFields[4];
        loadQuadPerLane<0, 8>(b, idLanes, loFields);
        loadQuadPerLane<4, 8>(b, idLanes, hiFields);
        VF lo[3], hi[3], far[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = hn::Sub(loFields[a], apexLanes[a]);
            hi[a] = hn::Sub(hiFields[a], apexLanes[a]);
            far[a] = hn::Max(hn::Abs(lo[a]), hn::Abs(hi[a]));
        }
        const VF slack = hn::Mul(slackScale, hn::Add(hn::Add(far[0], far[1]), far[2]));
        const VF negSlack = hn::Neg(slack);
        VU firstBand = hn::Set(du, edges + 1), lastBand = hn::Zero(du);
        MF reachesPrevious = hn::FirstN(df, n);  // band 0 has no top edge but the image's
        for (std::uint32_t k = 0; k < edges; ++k) {
            VF most[3], least[3];
            for (int a = 0; a < 3; ++a) {
                const VF u = hn::Set(df, up[k][a]);
                const VF atLo = hn::Mul(u, lo[a]), atHi = hn::Mul(u, hi[a]);
                most[a] = hn::Max(atLo, atHi);
                least[a] = hn::Min(atLo, atHi);
            }
            const MF reachesK = hn::AndNot(hn::Add(hn::Add(most[0], most[1]), most[2]) < negSlack, reachesPrevious);
            const auto reachesKU = hn::RebindMask(du, reachesK);
            firstBand = hn::IfThenElse(reachesKU, hn::Min(firstBand, hn::Set(du, k)), firstBand);
            lastBand = hn::IfThenElse(reachesKU, hn::Set(du, k), lastBand);
            reachesPrevious = hn::Not(hn::Add(hn::Add(least[0], least[1]), least[2]) > slack);
        }
        const auto lastReached = hn::RebindMask(du, reachesPrevious);
        firstBand = hn::IfThenElse(lastReached, hn::Min(firstBand, hn::Set(du, edges)), firstBand);
        lastBand = hn::IfThenElse(lastReached, hn::Set(du, edges), lastBand);
        hn::Store(firstBand, du, firstLanes);
        hn::Store(lastBand, du, lastLanes);
        std::copy(firstLanes, firstLanes + lanes, first + i);
        std::copy(lastLanes, lastLanes + lanes, last + i);
    }
}

// The box of the triangles' bounds of ids[0, count): the smallest lo and largest hi, lanes at
// a time, the lanes past the count repeating the last id (which changes no minimum or maximum).
// Minimum and maximum of finite floats are exact, so any order gives the same box but, where
// +0 and -0 meet, a zero's sign, which no comparison sees.
void BoundsOfTriangles(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, Box& box) {
    const DF df;
    const std::size_t n = hn::Lanes(df);
    const float* b = reinterpret_cast<const float*>(bounds);
    VF lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = hn::Set(df, kNoHitT);
        hi[a] = hn::Set(df, -kNoHitT);
    }
    alignas(64) std::uint32_t idLanes[64];
    for (std::uint32_t i = 0; i < count; i += std::uint32_t(n)) {
        laneIds(ids, i, std::min(std::uint32_t(n), count - i), idLanes);
        // The records four vectors ahead asked for, as bandsOfBounds does: a node's ids skip
        // through the frame's bounds.
        for (std::uint32_t k = i + 4 * std::uint32_t(n); k < std::min(count, i + 5 * std::uint32_t(n)); ++k)
            __builtin_prefetch(bounds + ids[k]);
        // A Bounds is 8 floats: lo and a pad, hi and a pad.
        VF loFields[4], hiFields[4];
        loadQuadPerLane<0, 8>(b, idLanes, loFields);
        loadQuadPerLane<4, 8>(b, idLanes, hiFields);
        for (int a = 0; a < 3; ++a) {
            lo[a] = hn::Min(lo[a], loFields[a]);
            hi[a] = hn::Max(hi[a], hiFields[a]);
        }
    }
    for (int a = 0; a < 3; ++a) {
        box.lo[a] = hn::GetLane(hn::MinOfLanes(df, lo[a]));
        box.hi[a] = hn::GetLane(hn::MaxOfLanes(df, hi[a]));
    }
}

std::int64_t CompiledTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::simd
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace dacrt::simd {

HWY_EXPORT(PartitionRays);
HWY_EXPORT(EndRaysHitInBox);
HWY_EXPORT(PartitionTrianglesOnFace);
HWY_EXPORT(IntersectBatch);
HWY_EXPORT(IntersectBatchInGroups);
HWY_EXPORT(IntersectBatchInSegmentGroups);
HWY_EXPORT(BoundsOfRays);
HWY_EXPORT(GatherLeafTriangles);
HWY_EXPORT(CompiledTarget);
HWY_EXPORT(BandsOfBounds);
HWY_EXPORT(BoundsOfTriangles);
HWY_EXPORT(ClassifyFacing);
HWY_EXPORT(FirstRegions);

std::uint32_t slabOf(float x, const float* boundary, std::uint32_t count) {
    const float* first = boundary + 1;
    const float* last = boundary + count;  // boundary[count] itself is not searched
    const std::int64_t k = std::upper_bound(first, last, x) - first;
    return std::uint32_t(std::clamp<std::int64_t>(k, 0, std::int64_t(count) - 1));
}

namespace {
// Where firstRegionOfRay's walk starts: one slab behind the origin's in the travel direction,
// or the first (last) slab for a ray that starts below (above) the box moving up (down).
std::uint32_t walkStart(float origin, float dir, const RegionSlabs& s) {
    const std::uint32_t last = s.count - 1;
    const bool down = dir < 0.0f;
    if (dir > 0.0f && origin < s.boundary[0]) return 0;
    if (down && origin > s.boundary[s.count]) return last;
    const std::int64_t behind = std::int64_t(slabOf(origin, s.boundary, s.count)) + (down ? 1 : -1);
    return std::uint32_t(std::clamp<std::int64_t>(behind, 0, last));
}
}  // namespace

std::uint32_t firstRegionOfRay(const Ray& ray, const RegionSlabs& s) {
    if (!shared::rayMayCrossCell(ray, s.sceneLo, s.sceneHi, kNoHitT)) return kNoRegion;
    const float dir = ray.dir[s.axis];
    const int step = dir < 0.0f ? -1 : 1;
    for (std::int64_t k = walkStart(ray.origin[s.axis], dir, s); k >= 0 && k < std::int64_t(s.count); k += step)
        if (shared::rayMayCrossCell(ray, s.wideLo[k], s.wideHi[k], kNoHitT)) return std::uint32_t(k);
    return kNoRegion;
}

void firstRegionsOfRays(const Ray* rays, std::size_t count, const RegionSlabs& s, std::uint32_t* region) {
    if (s.count > kMostRegionsInLanes || count > kMaxRays) {
        for (std::size_t i = 0; i < count; ++i) region[i] = firstRegionOfRay(rays[i], s);
        return;
    }
    HWY_DYNAMIC_DISPATCH(FirstRegions)(rays, count, s, region);
}

void classifyFacing(const Triangle* triangles, std::uint32_t count, const glm::vec3& origin, std::uint8_t* verdict) {
    HWY_DYNAMIC_DISPATCH(ClassifyFacing)(triangles, count, origin, verdict);
}

void bandsOfBounds(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, const glm::vec3& apex,
                   const glm::vec3* up, std::uint32_t edges, std::uint32_t* first, std::uint32_t* last) {
    HWY_DYNAMIC_DISPATCH(BandsOfBounds)(bounds, ids, count, apex, up, edges, first, last);
}

Box boundsOfTriangles(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count) {
    Box box;
    if (count > 0) HWY_DYNAMIC_DISPATCH(BoundsOfTriangles)(bounds, ids, count, box);
    return box;
}

std::uint32_t endRaysHitInBox(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count, const Box& box,
                              bool anyHit) {
    return HWY_DYNAMIC_DISPATCH(EndRaysHitInBox)(rays, hits, ids, count, box, anyHit);
}

std::uint32_t partitionRaysMayCrossCell(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count,
                                        const Box& cell, SharedRayFields shared, std::uint32_t* scratch) {
    return HWY_DYNAMIC_DISPATCH(PartitionRays)(rays, hits, ids, count, cell, shared, scratch);
}

std::uint32_t partitionTrianglesOnFace(const TriangleFaces& faces, std::uint32_t* ids, std::uint32_t count, int axis,
                                       bool lowSide, float bound, std::uint32_t* scratch, FaceSide keep) {
    return HWY_DYNAMIC_DISPATCH(PartitionTrianglesOnFace)(faces, ids, count, axis, lowSide, bound, scratch, keep);
}

void gatherLeafTriangles(const Triangle* triangles, const std::uint32_t* triIds, std::uint32_t count,
                         LeafTriangles& batch) {
    HWY_DYNAMIC_DISPATCH(GatherLeafTriangles)(triangles, triIds, count, batch);
}

void intersectBatch(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                    const LeafTriangles& batch, bool anyHit) {
    HWY_DYNAMIC_DISPATCH(IntersectBatch)(rays, hits, rayIds, rayCount, batch, anyHit);
}

RayPacket boundsOfRays(const Ray* rays, const std::uint32_t* rayIds, std::uint32_t count) {
    return HWY_DYNAMIC_DISPATCH(BoundsOfRays)(rays, rayIds, count);
}

std::uint64_t intersectBatchInGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                                     const LeafTriangles& batch, float widening) {
    return HWY_DYNAMIC_DISPATCH(IntersectBatchInGroups)(rays, hits, rayIds, rayCount, batch, widening);
}

std::uint64_t intersectBatchInSegmentGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds,
                                            std::uint32_t rayCount, const LeafTriangles& batch, const Box& cell,
                                            float widening, bool anyHit) {
    return HWY_DYNAMIC_DISPATCH(IntersectBatchInSegmentGroups)(rays, hits, rayIds, rayCount, batch, cell, widening,
                                                               anyHit);
}

std::string activeTarget() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(CompiledTarget)()); }

std::vector<std::string> availableTargets() {
    std::vector<std::string> names;
    for (std::int64_t t : hwy::SupportedAndGeneratedTargets()) names.push_back(hwy::TargetName(t));
    return names;
}

void forceTarget(const std::string& name) {
    if (name.empty()) {
        hwy::SetSupportedTargetsForTest(0);
        return;
    }
    hwy::SetSupportedTargetsForTest(0);
    for (std::int64_t t : hwy::SupportedAndGeneratedTargets())
        if (name == hwy::TargetName(t)) {
            hwy::SetSupportedTargetsForTest(t);
            return;
        }
    throw std::invalid_argument("no SIMD target named " + name + " is available here");
}

}  // namespace dacrt::simd
#endif
