#pragma once
// The data-parallel kernels of the default DACRT path (docs/cpu-reference.md, "SIMD"): the
// ray/cell filter, the triangle-bounds/cell filter and the leaf's watertight test, 4 to 16
// lanes at a time through Google Highway, whose instruction set is chosen at run time
// (AVX-512, AVX2, SSE4, ... down to portable scalar code), so one binary serves every x86-64.
//
// Each kernel computes, lane by lane, the same IEEE operations in the same order as the
// scalar predicate it replaces (shaders/predicates.glsl), with the same min/max operand
// order and no contraction, so its answers are the scalar ones bit for bit
// (tests/cpu/test_simd_kernels.cpp runs both side by side on every compiled target).
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "cpu/ray_packet.hpp"
#include "cpu/triangle_faces.hpp"

namespace dacrt::simd {

// Ids move through 32-bit gather offsets: the kernels take at most this many rays
// (16 floats each) or triangles (12 floats each); larger frames use the scalar path.
constexpr std::uint64_t kMaxRays = (std::uint64_t(1) << 31) / 16;
constexpr std::uint64_t kMaxTriangles = (std::uint64_t(1) << 31) / 16;

// Room past the ids a partition may park in scratch, for whole-vector stores.
constexpr std::uint32_t kScratchSlack = 64;

// What every ray a partition reads has of rays[0]'s, bit for bit, so that one broadcast gives
// each lane the value a load would:
// - Start: the origin and tmin (raysShareStart() in frame_geometry.hpp: primary rays);
// - Segment: tmin, and as the best hit so far rays[0].tmax, which every id's hits[id].t must
//   then be (any-hit rays of one segment, raysShareSegment(): a live one has no hit yet, and
//   its hit is missHit's, at the segment's end). The Hit records are not read.
// - OwnSegment: nothing shared, but the rays are any-hit rays as Segment's, each of its own
//   segment, so each id's hits[id].t is its own ray's tmax (float 11 of the Ray, loaded with
//   invDir): the Hit records are not read either (a frame's passes traced together).
enum class SharedRayFields : std::uint8_t { None, Start, Segment, OwnSegment };

// Stable partition of ids[0, count): the ids whose ray may cross the (already widened) cell
// before its best hit so far (shared::rayMayCrossCell with hits[id].t) first, in their order;
// the others after them, in theirs. Returns how many pass. scratch holds count +
// kScratchSlack ids.
std::uint32_t partitionRaysMayCrossCell(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count,
                                        const Box& cell, SharedRayFields shared, std::uint32_t* scratch);

// The rays of ids[0, count) whose hits end them in box (a hit at all where anyHit, else
// shared::hitEndsInBox) swapped to the front, one at a time in order, exactly as
// DacrtTraversal's scalar loop swaps them. Returns how many.
std::uint32_t endRaysHitInBox(const Ray* rays, const Hit* hits, std::uint32_t* ids, std::uint32_t count, const Box& box,
                              bool anyHit);

// The same partition for triangles whose bounds are known to overlap a cell that differs
// from this one only in one face, on `axis`: what shared::boundsOverlap with this cell
// answers then is the one comparison that face adds, lo[axis] <= bound for a new high face
// (lowSide) or hi[axis] >= bound for a new low face. One gather per id instead of six.
// FaceSide::Beyond keeps the others first instead: the triangles wholly beyond the face.
enum class FaceSide { Reaching, Beyond };
std::uint32_t partitionTrianglesOnFace(const TriangleFaces& faces, std::uint32_t* ids, std::uint32_t count, int axis,
                                       bool lowSide, float bound, std::uint32_t* scratch,
                                       FaceSide keep = FaceSide::Reaching);
inline std::uint32_t partitionTrianglesOnFace(const Bounds* bounds, std::uint32_t* ids, std::uint32_t count, int axis,
                                              bool lowSide, float bound, std::uint32_t* scratch,
                                              FaceSide keep = FaceSide::Reaching) {
    return partitionTrianglesOnFace(TriangleFaces{bounds, nullptr, 0}, ids, count, axis, lowSide, bound, scratch, keep);
}

// Up to kLeafBatch triangles of a leaf in structure-of-arrays form: coordinate c of vertex k
// of triangle j is vertex[k][c][j]. Lanes past `count` are padding and never hit.
constexpr std::uint32_t kLeafBatch = 64;
struct LeafTriangles {
    alignas(64) float vertex[3][3][kLeafBatch];
    alignas(64) std::uint32_t prim[kLeafBatch];
    alignas(64) std::uint32_t cullBackFace[kLeafBatch];  // Triangle::cullBackFace
    std::uint32_t count = 0;
};

// Copies triIds[0, count) (count <= kLeafBatch) of triangles into batch.
void gatherLeafTriangles(const Triangle* triangles, const std::uint32_t* triIds, std::uint32_t count,
                         LeafTriangles& batch);

// The watertight test of each ray rays[rayIds[r]], r < rayCount, against every triangle of
// batch; its hit becomes the first under the tie rule (smaller t, then smaller id) of the
// hit it had and the batch's hits with t > tmin: what testTriangle over the batch gives, in
// any order, since the rule is a total order on distinct ids. With anyHit (HitQuery::Any) a ray
// that has a hit (prim not kMissPrim) keeps it, and one that has none takes the first hit
// found that the tie rule puts before its segment's end, if any: a hit wherever the
// closest-hit kernel finds one, not necessarily the same (docs/correctness.md, "Any hit").
void intersectBatch(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                    const LeafTriangles& batch, bool anyHit = false);

// The bounds of rays[rayIds[0, count)] (count > 0) as startPacketBounds and addToPacketBounds
// (ray_packet.hpp) make them, lanes at a time (begin and end left 0).
RayPacket boundsOfRays(const Ray* rays, const std::uint32_t* rayIds, std::uint32_t count);

// intersectBatch for rays that share their start (SharedRayFields::Start: every ray has
// rays[0]'s origin and tmin), in groups of up to kLeafGroupRays consecutive ids: each group
// tests only the triangles whose bounds, widened by `widening` (twice the filter margin),
// packetMayCrossCell (ray_packet.hpp) says the group may cross, one triangle at a time with
// the group's rays in lanes. The same hits as intersectBatch: a triangle the test reports a
// hit on lies within the margin of its bounds on the ray's segment (docs/correctness.md,
// "Leaf groups"). Returns the ray/triangle tests skipped.
constexpr std::uint32_t kLeafGroupRays = 16;
std::uint64_t intersectBatchInGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds, std::uint32_t rayCount,
                                     const LeafTriangles& batch, float widening);

// intersectBatch for rays with their own starts and segments, in groups of up to
// kLeafGroupRays consecutive ids: each group tests only the triangles whose bounds, widened by
// `widening` (twice the filter margin), overlap the box of the group's segments from their
// origins to their best t so far, except where that box holds `cell` (the leaf's cell widened
// by the margin, which every triangle's bounds overlap), or where narrowing cannot pay (one
// vector of triangles, fewer than 64 rays, or a leaf whose first two groups saved little). The
// same hits as intersectBatch: a hit the test reports lies within the margin of its triangle's
// bounds at a point of the ray's exact segment (docs/correctness.md, "Leaf groups"). Returns
// the ray/triangle tests skipped.
std::uint64_t intersectBatchInSegmentGroups(const Ray* rays, Hit* hits, const std::uint32_t* rayIds,
                                            std::uint32_t rayCount, const LeafTriangles& batch, const Box& cell,
                                            float widening, bool anyHit);

// The box of the bounds of triangles ids[0, count): the smallest lo and the largest hi, exactly
// (an empty Box where count is 0).
Box boundsOfTriangles(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count);

// For the bounds of ids[0, count) (bounds[0, count) where ids is null), the first and the
// last of the bands between `edges` band edges that BandEdges::bandsOf finds (image_bands.hpp:
// the edges' normals up[0, edges) through apex), into first[0, count) and last[0, count).
void bandsOfBounds(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, const glm::vec3& apex,
                   const glm::vec3* up, std::uint32_t edges, std::uint32_t* first, std::uint32_t* last);

// The regions of a scene division as the ray binning reads them (scene_division.cpp): `count`
// (at least 1) slabs along `axis` between ascending boundaries boundary[0] .. boundary[count]
// (the scene box's faces on that axis at the ends), their boxes widened by the filter margin,
// and the widened scene box, which holds every region's box.
struct RegionSlabs {
    int axis = 0;
    std::uint32_t count = 0;
    const float* boundary = nullptr;  // count + 1
    const glm::vec3* wideLo = nullptr;
    const glm::vec3* wideHi = nullptr;
    glm::vec3 sceneLo{}, sceneHi{};
};
constexpr std::uint32_t kNoRegion = 0xFFFFFFFFu;
// The SIMD binning tests every region for each vector of rays, where the walk ray by ray
// tests one or two: beyond this many regions the rays go one by one.
constexpr std::uint32_t kMostRegionsInLanes = 32;

// The slab of `count` (boundary[0 .. count]) holding x: boundary[1 .. count - 1] searched,
// clamped to [0, count).
std::uint32_t slabOf(float x, const float* boundary, std::uint32_t count);
// The region a ray meets first in its travel direction (kNoRegion: it misses the widened
// scene box, or crosses no region): the walk starts one slab behind the origin's (so that
// rounding in that guess never skips the true first region; at the first or last slab for an
// origin outside the box on the side the ray comes from) and tests shared::rayMayCrossCell
// (unbounded) region by region. The rule, ray by ray.
std::uint32_t firstRegionOfRay(const Ray& ray, const RegionSlabs& s);
// firstRegionOfRay of rays[0, count) into region[0, count): the regions' tests lanes at a
// time, the same answers for rays of finite origins (every ray a batch or a maker gives);
// ray by ray beyond kMostRegionsInLanes regions or kMaxRays rays.
void firstRegionsOfRays(const Ray* rays, std::size_t count, const RegionSlabs& s, std::uint32_t* region);

// Asks for both cache lines a 48-byte triangle may straddle, before it is read: the leaves'
// and the secondary rays' triangles lie anywhere in a scene's array.
inline void prefetchTriangle(const Triangle& t) {
    const char* bytes = reinterpret_cast<const char*>(&t);
    __builtin_prefetch(bytes);
    __builtin_prefetch(bytes + sizeof(Triangle) - 1);
}

// The back-face skip's verdict on triangles[0, count) seen from origin, certified in float32
// lanes: kKeep where facesAwayFrom (triangle_skips.hpp, float64) is false (front-facing, or not
// single-sided), kDrop where it is true, kUndecided where float32 cannot tell within its
// error bound (the caller then asks facesAwayFrom). Never kKeep or kDrop against it.
enum FacingVerdict : std::uint8_t { kKeep = 0, kDrop = 1, kUndecided = 2 };
void classifyFacing(const Triangle* triangles, std::uint32_t count, const glm::vec3& origin, std::uint8_t* verdict);

// The instruction set the kernels run on now ("AVX3" is AVX-512), and every one this
// binary holds that the machine supports, best first.
std::string activeTarget();
std::vector<std::string> availableTargets();
// Restricts the dispatch to one of availableTargets() (tests); "" restores the best.
void forceTarget(const std::string& name);

}  // namespace dacrt::simd
