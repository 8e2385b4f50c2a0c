#pragma once
// Sequential divide-and-conquer ray tracing (Mora 2011) over in-place id arrays: the
// building block of both the cpu-seq backend and every work item of the parallel scheme.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "cpu/predicates.hpp"
#include "cpu/ray_packet.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/simd_kernels.hpp"
#include "cpu/options.hpp"
#include "cpu/ray_sampling.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// Which live rays a work item of the parallel scheme may finish, because no later work item
// can change their result: along `axis`, rays that do not move (direction 0, after Step 1),
// or rays moving `direction` that cannot reach the region traced now before their best hit
// (regions are consecutive slabs, so they cannot reach any further one either). The gpu
// kernel applies the same rule (kKeepStill, kKeepStuckHigh, kKeepStuckLow).
struct RetireRule {
    int axis = -1;      // -1: retire nothing
    int direction = 0;  // 0: rays with dir[axis] == 0; +1 / -1: non-crossing rays moving that way
};

// Ids a traversal's stable partitions park the rejected ids in: at least as many as the
// longest ray or triangle id range it is given.
std::uint64_t partitionScratchIds(std::uint64_t rayRange, std::uint64_t triRange);

// Packets' working arrays, one set per worker: rays grouped by tile, the rays of a node's
// packets when it goes on ray by ray, the packets and their ids (partitioned like ray ids),
// and per-ray "finished" flags shared by all workers (each ray belongs to one work item).
struct PacketBuffers {
    std::uint32_t* packetRays = nullptr;  // partitionScratchIds ids
    std::uint32_t* flushRays = nullptr;   // partitionScratchIds ids
    RayPacket* packets = nullptr;         // packetTiles()
    std::uint32_t* packetIds = nullptr;   // packetTiles()
    std::uint32_t* tileCounts = nullptr;  // packetTiles() + 1
    std::uint8_t* rayDone = nullptr;      // one per ray of the frame, zeroed
};
// Whether a traversal of these (resolved) options on this frame runs the SIMD kernels: the
// default tests, and counts whose ids fit the kernels' 32-bit gather offsets.
bool usesSimd(const FrameGeometry& geometry, const DacrtOptions& options);
bool usesSimd(std::uint64_t rays, std::uint64_t triangles, const DacrtOptions& options);
// Tiles of the frame's image, 0 when the frame has no packets.
std::uint64_t packetTiles(const FrameGeometry& geometry);
// Whether a traversal of these options on this frame uses packets.
bool usesPackets(const FrameGeometry& geometry, const DacrtOptions& options);
// The memory one worker's packet buffers take (0 without packets), and the frame's flags.
void planPacketBuffers(const FrameGeometry& geometry, const DacrtOptions& options, std::uint64_t scratchIds,
                       unsigned workers, MemoryPlan& plan);

// Owns what planPacketBuffers planned.
struct PacketStorage {
    std::vector<std::uint32_t> packetRays, flushRays, packetIds, tileCounts;
    std::vector<RayPacket> packets;
    std::vector<std::uint8_t> rayDone;
    std::uint64_t scratchIds = 0, tiles = 0;
    PacketStorage(const FrameGeometry& geometry, const DacrtOptions& options, std::uint64_t scratchIds, unsigned workers);
    PacketBuffers forWorker(unsigned worker);
};

// The arrays a traversal permutes and updates. The last two serve the SIMD path of the
// default options (without scratch the scalar path runs): scratch holds partitionScratchIds
// of the ranges traced.
struct TraversalBuffers {
    Hit* hits = nullptr;
    std::uint32_t* rayIds = nullptr;
    std::uint32_t* triIds = nullptr;
    std::uint32_t* scratch = nullptr;
    PacketBuffers packets;  // used when usesPackets()
    // Every ray has the first one's tmin and tmax, bit for bit (raysShareSegment()), found
    // where the hits start (a frame's rays may change after the frame is made); any-hit rays
    // then share their best t while live.
    bool raysShareSegment = false;
};

// A box widened by the filter margin on every side: the cell its filters test.
inline Box widenedBox(const Box& b, float margin) {
    Box w;
    w.lo = b.lo - glm::vec3(margin);
    w.hi = b.hi + glm::vec3(margin);
    return w;
}

// The axis a node splits along, where the sampled cost does not choose: its box's longest.
inline int longestAxis(const Box& b) {
    const glm::vec3 e = b.extent();
    return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
}

// The spatial median split of a box along axis.
inline float spatialMedian(const Box& b, int axis) { return 0.5f * (b.lo[axis] + b.hi[axis]); }

// Whether a split's low child is visited first: always where each ray's own order is kept
// (ChildOrder::PerRay: the rays moving up, or every ray for any hit), else where the rays come
// from that side (nearSide: FrameGeometry::nearSide).
inline bool lowChildFirst(ChildOrder order, const glm::vec3& nearSide, int axis, float split) {
    return order == ChildOrder::PerRay || nearSide[axis] <= split;
}

// Whether a node ends as a leaf before any sampled cost is asked, under resolved options:
// too few items (fewItems: live rays under rayLimit, or packets under packetFlush), too few
// triangles, too deep, stalled (splits in a row that kept every item and triangle), or a
// split position on axis that is not inside its box.
inline bool endsAsLeaf(const Box& box, int axis, float split, bool fewItems, std::uint32_t triangles,
                       std::uint32_t depth, std::uint32_t stalls, const DacrtOptions& options) {
    return fewItems || triangles < options.triLimit || depth >= options.maxDepth ||
           stalls >= DACRT_MAX_STALLED_SPLITS || !(split > box.lo[axis] && split < box.hi[axis]);
}

// A node whose live rays number at least this many times its triangles traces inside the box
// of its triangles' bounds (DacrtTraversal::shrunkBox) rather than its cell. Shrinking every
// node made the Dragon's passes about 20% slower (its triangles outnumber its rays nearly
// everywhere, and the bounds cost a pass over them); ratios of 0.5 to 4 measured alike on the
// Bunny's, the room's and the Dragon's passes (docs/benchmarks.md, "Tight node boxes"). The
// gpu kernel takes the same ratio (kTightBoxRays; 1 and 2 alike on lavapipe, 4 slower:
// docs/gpu.md, "Tight node boxes in the kernel").
constexpr std::uint64_t kTightBoxRaysPerTriangle = 2;

class DacrtTraversal {
public:
    DacrtTraversal(const FrameGeometry& geometry, const DacrtOptions& options, const TraversalBuffers& buffers,
                   Counters& counters);

    // Traces the live rays rayIds[terminated, rayEnd) against triIds[triBegin, triEnd)
    // inside box. Rays whose final hit is found are swapped to position `terminated`, which
    // advances past them; the others keep their best hit so far (it bounds later work).
    // Returns the end of the rays that cross the box (the others are moved behind them).
    // Rays that `retire` selects are finished too (moved before `terminated`).
    std::uint32_t trace(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                        std::uint32_t triEnd, const RetireRule& retire = {});

    // The recursion below a node whose live rays rayIds[terminated, rayEnd) already cross its
    // widened box and whose triangles triIds[triBegin, triEnd) already overlap it: a subtree of
    // a DACRT whose upper levels were divided elsewhere (subtrees.hpp), at their depth and
    // stall count. Rays and triangles move as trace() moves them.
    void traceBelow(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                    std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls) {
        node(box, terminated, rayEnd, triBegin, triEnd, depth, stalls);
    }


private:
    template <typename FilterItems, typename Descend>
    bool splitNode(const Box& box, const std::uint32_t& itemBegin, std::uint32_t itemEnd, std::uint32_t triBegin,
                   std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls, bool fewItems, bool sampleRays,
                   FilterItems filterItems, Descend descend);
    bool sampledSplit(const Box& box, int& axis, std::uint32_t rayBegin, std::uint32_t rayEnd, std::uint32_t triBegin,
                      std::uint32_t triEnd, float& split);
    // A node of rays: its cell shrunk (tightenedBox), then nodeInBox, which splits the box or
    // makes it a leaf (a flushed packet node's rays start there, their box already shrunk).
    void node(const Box& cell, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
              std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls);
    void nodeInBox(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                   std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls);
    // Tight node boxes (docs/correctness.md): the cell shrunk to the box of the triangles'
    // bounds widened by the margin, where `rays` outnumber them kTightBoxRaysPerTriangle to one
    // and that box is smaller but not empty; else none. tightenedBox gives that box or the cell,
    // and moves the rays that miss the shrunk box (widened) behind the node's.
    std::optional<Box> shrunkBox(const Box& cell, std::uint64_t rays, std::uint32_t triBegin, std::uint32_t triEnd);
    Box tightenedBox(const Box& cell, std::uint32_t& terminated, std::uint32_t& rayEnd, std::uint32_t triBegin,
                     std::uint32_t triEnd);
    void leaf(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
              std::uint32_t triEnd);
    std::uint32_t filterRays(const Box& cell, std::uint32_t begin, std::uint32_t end);
    // filterRays over the rays moving `moving` along axis (+1: up or not at all, -1: down, 0: all).
    // With moving 0, the rays of [certainFrom, end) are known to cross the cell: they pass
    // untested, behind the tested ones that pass.
    std::uint32_t filterRaysMoving(const Box& cell, std::uint32_t begin, std::uint32_t end, int axis, int moving,
                                   std::uint32_t certainFrom);
    void tracePackets(const Box& box, std::uint32_t& terminated, std::uint32_t crossing, std::uint32_t triBegin,
                      std::uint32_t triEnd);
    std::uint32_t buildPackets(std::uint32_t begin, std::uint32_t end);
    void nodePackets(const Box& nodeCell, std::uint32_t packetBegin, std::uint32_t packetEnd, std::uint32_t triBegin,
                     std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls);
    std::uint32_t filterPackets(const Box& cell, std::uint32_t begin, std::uint32_t end);
    void flushPackets(const Box& box, std::uint32_t packetBegin, std::uint32_t packetEnd, std::uint32_t triBegin,
                      std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls);
    void leafSimd(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                  std::uint32_t triEnd);
    void endRaysHitInBox(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd);
    template <typename PrepareRay, typename TestTriangle>
    void leafWith(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                  std::uint32_t triEnd, PrepareRay prepare, TestTriangle test);
    // cell is child widened by the filter margin; the Mora filter reads child itself. cell
    // differs from the parent's widened cell in one face, on axis (the high face when child is
    // the low one), and the SIMD path tests that face alone: never "no" where the full test
    // says "maybe", and the same answer wherever the node's triangles overlap the node's
    // widened cell, which the roots' do (scene bounds; region binning), and so every child's
    // and every shrunk box's (docs/correctness.md, "Tight node boxes").
    std::uint32_t filterTriangles(const Box& child, const Box& cell, std::uint32_t begin, std::uint32_t end, int axis,
                                  bool lowChild);
    // The second child's triangles, when the first child's subtree has left its own (those
    // filterTriangles kept) at [begin, siblingEnd) and the ones it dropped behind them: the
    // sibling's triangles that do not overlap cell move first, so that this child's are
    // [returned, the node's end): the sibling's that reach past the split, then those only
    // this child has (a triangle the sibling dropped lies beyond the sibling's face, so within
    // this child's cell). Returns where they begin. Only where triangleOrderFree_.
    std::uint32_t filterTrianglesAfterSibling(const Box& cell, std::uint32_t begin, std::uint32_t siblingEnd, int axis,
                                              bool lowChild);
    // The bounds filter of both: the triangles of [begin, end) that reach into cell (Reaching)
    // or those wholly beyond its face on axis (Beyond) first.
    std::uint32_t partitionTrianglesByBounds(const Box& cell, std::uint32_t begin, std::uint32_t end, int axis,
                                             bool lowChild, simd::FaceSide keep);
    float splitPosition(const Box& box, int axis, std::uint32_t triBegin, std::uint32_t triEnd) const;

    const Ray* rays_;
    const Triangle* triangles_;
    const Bounds* triangleBounds_;
    simd::TriangleFaces triangleFaces_;  // what the SIMD triangle filter reads
    ChildOrder order_;
    glm::vec3 orderPoint_;  // FrameGeometry::nearSide
    bool anyHit_;           // HitQuery::Any: a ray ends at its first hit
    // No split reads the order of a node's triangle ids (the spatial median, the leaf limits)
    // and the filter is the bounds test: a second child may then take its triangles from its
    // sibling's (filterTrianglesAfterSibling) in another order than a filter of the node's.
    bool triangleOrderFree_;
    float margin_;
    DacrtOptions options_;
    Hit* hits_;
    std::uint32_t* rayIds_;
    std::uint32_t* triIds_;
    std::uint32_t* scratch_;
    // What the ray filter may broadcast from the first ray: the start of primary rays, or the
    // segment of any-hit rays (whose live ones have no hit, so their best t is the segment's end).
    simd::SharedRayFields sharedRayFields_;
    bool simd_;
    bool packets_;
    PacketBuffers packet_;
    std::uint32_t imageWidth_;
    std::uint32_t tiles_;  // the default options (bounds filter, watertight float32 test) on SIMD kernels
    simd::LeafTriangles batch_;
    Counters& counters_;
};

// Tests one ray against one triangle and keeps the better hit under the tie rule.
inline void testTriangle(const Ray& ray, const Triangle& tri, std::uint32_t prim, Hit& best) {
    const shared::TriangleHit h = shared::intersectWatertight(ray, tri.v0, tri.v1, tri.v2, tri.cullBackFace != 0u);
    if (h.hit && h.t > ray.tmin && shared::hitPrecedes(h.t, prim, best.t, best.prim)) best = Hit{h.t, prim, h.u, h.v};
}

// The leaf tests of the non-default options (docs/benchmarks.md prices them).
void testTriangleMollerTrumbore(const Ray& ray, const Triangle& tri, std::uint32_t prim, Hit& best);
struct RayF64;
void testTriangleF64(const RayF64& ray, const Triangle& tri, std::uint32_t prim, Hit& best);

}  // namespace dacrt
