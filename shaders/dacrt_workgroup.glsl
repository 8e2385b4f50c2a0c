// Workgroup-wide building blocks of the DACRT kernel: synchronisation, prefix sums, stable
// partitions of the id arrays, and leaves. Every function here is called in uniform control
// flow by the whole workgroup and returns the same value to every invocation.
#ifndef DACRT_WORKGROUP_GLSL
#define DACRT_WORKGROUP_GLSL

#include "stage_clocks.glsl"
#include "ray_packets.glsl"

// Orders every invocation of the subgroup's earlier accesses before its later ones: a subgroup
// barrier, but where the workgroup is one subgroup run in lockstep (kLockstepSubgroups), memory
// barriers only.
void subgroupSync() {
    subgroupMemoryBarrierBuffer();
    subgroupMemoryBarrierShared();
    if (!kLockstepSubgroups) subgroupBarrier();
}

// Makes buffer and shared writes of every invocation visible to the whole workgroup. A
// workgroup of one subgroup needs only a subgroup barrier (none in lockstep).
void workgroupSync() {
    if (kLockstepSubgroups || gl_NumSubgroups == 1) {
        subgroupSync();
    } else {
        memoryBarrierBuffer();
        memoryBarrierShared();
        barrier();
    }
}

// Exclusive prefix sum of value over the workgroup, in invocation order; total gets the sum.
// Subgroup scans, then the subgroup totals through shared memory; no subgroup size assumed.
uint workgroupExclusiveSum(uint value, out uint total) {
    uint inclusive = subgroupInclusiveAdd(value);
    uint subgroupTotal = subgroupAdd(value);  // in uniform control flow: every lane takes part
    if (kLockstepSubgroups || gl_NumSubgroups == 1) {
        total = subgroupTotal;
        return inclusive - value;
    }
    if (subgroupElect()) sSubgroupTotals[gl_SubgroupID] = subgroupTotal;
    memoryBarrierShared();
    barrier();
    // Lane k of every subgroup holds subgroup k's total (the host keeps the number of
    // subgroups within one subgroup's size): two subgroup sums, no loop.
    uint k = gl_SubgroupInvocationID;
    uint t = k < gl_NumSubgroups ? sSubgroupTotals[k] : 0u;
    uint before = subgroupAdd(k < gl_SubgroupID ? t : 0u);
    total = subgroupAdd(t);
    barrier();  // sSubgroupTotals is reused by the next call
    return before + inclusive - value;
}

// llvmpipe (Mesa's CPU driver, under lavapipe) ends every loop of a shader invocation once
// all its loops together have iterated 65535 times, silently. A loop run after the real work
// tells: if it cannot complete `iterations` (uniform, > 0) passes, the limiter has fired.
bool loopLimiterFired(uint iterations) {
    uint done = 0;
    for (uint i = 0; i < iterations; ++i) ++done;
    return done != iterations;
}

// What a ray partition keeps in front.
const uint kKeepCrossing = 0u;     // rays that may cross the (widened) cell
const uint kKeepFinished = 1u;     // rays whose best hit ends them in the (unwidened) box
const uint kKeepStill = 2u;        // rays with no motion along gAxis
const uint kKeepStuckHigh = 3u;    // rays moving up gAxis that cannot reach the cell
const uint kKeepStuckLow = 4u;     // rays moving down gAxis that cannot reach the cell
// Rays that may cross the cell and move up (or not at all) along axis a: kKeepCrossingUp + 2a;
// those moving down: kKeepCrossingUp + 2a + 1 (the children of a kOrderPerRay split).
const uint kKeepCrossingUp = 6u;
// Rules 12 and up: not rays' crossing. Packets that may cross the (widened) cell (their ids are
// packet ids), and rays that have their final hit (rayDone).
const uint kKeepPacketCrossing = 12u;
const uint kKeepDone = 13u;

uint crossingMovingRule(int axis, bool down) {
    return kKeepCrossingUp + 2u * uint(axis) + (down ? 1u : 0u);
}

// A ray with only its origin and tmin read, from push constants where all rays share them
// (llvmpipe loads a buffer component one invocation at a time, so every field counts).
Ray rayStart(uint id) {
    Ray ray;
    ray.origin = kSharedStart ? gRayOrigin : RAYS(id).origin;
    ray.tmin = kSharedStart || kSharedSegment ? gRayTmin : RAYS(id).tmin;
    return ray;
}

// The best hit a live ray has so far: its start where any-hit rays share their segment.
Hit liveRayHit(uint id) {
    if (!kSharedSegment) return HITS(id);
    Hit start;
    start.t = gRayTmax;
    start.prim = kMissPrim;
    start.u = 0.0;
    start.v = 0.0;
    return start;
}

float liveRayBestT(uint id) {
    return kSharedSegment ? gRayTmax : HITS(id).t;
}

// The fields of a ray that its filters read: origin, tmin and invDir.
Ray filterRay(uint id) {
    Ray ray = rayStart(id);
    ray.invDir = RAYS(id).invDir;
    return ray;
}

bool keepRay(uint id, uint rule, vec3 lo, vec3 hi) {
    Ray ray = filterRay(id);
    float bestT = liveRayBestT(id);
    if (rule == kKeepCrossing) return rayMayCrossCell(ray, lo, hi, bestT);
    if (rule == kKeepFinished) return HITS(id).prim != kMissPrim && (kAnyHit || hitEndsInBox(ray, lo, hi, bestT));
    if (rule >= kKeepCrossingUp && rule < kKeepPacketCrossing) {
        uint axis = (rule - kKeepCrossingUp) >> 1u;
        bool down = ((rule - kKeepCrossingUp) & 1u) == 1u;
        return (ray.invDir[axis] < 0.0) == down && rayMayCrossCell(ray, lo, hi, bestT);  // invDir has dir's sign
    }
    float d = ray.invDir[gAxis];  // 0 exactly where dir is 0 (slabInterval)
    if (rule == kKeepStill) return d == 0.0;
    bool moving = rule == kKeepStuckHigh ? d > 0.0 : d < 0.0;
    return moving && !rayMayCrossCell(ray, lo, hi, bestT);
}

// Ids one invocation takes per step of a partition: a run of consecutive ids, so that a scan
// and a loop iteration serve four ids.
const uint kIdsPerInvocation = 4u;
const uint kPartitionChunk = kWorkgroupSize * kIdsPerInvocation;

// Loop iterations (llvmpipe's unit of account) a partition of n ids costs, at most.
uint partitionCost(uint n) {
    return 2u * ((n + kPartitionChunk - 1u) / kPartitionChunk) + 2u;
}

uint leafLanesPerRay(uint rayCount);

// ... the ray/triangle tests of rayCount rays against triCount triangles (leafTests) ...
uint leafTestCost(uint rayCount, uint triCount) {
    uint lanes = leafLanesPerRay(rayCount);
    uint raysPerPass = gl_NumSubgroups * (gl_SubgroupSize / lanes);
    uint passes = (rayCount + raysPerPass - 1u) / raysPerPass;
    uint tiles = (triCount + gl_SubgroupSize - 1u) / gl_SubgroupSize;
    uint perTile = 2u + (gl_SubgroupSize + lanes - 1u) / lanes;
    return passes * (2u + tiles * perTile + lanes);
}

// ... and a whole leaf, its final partition included.
uint leafCost(uint rayCount, uint triCount) {
    return leafTestCost(rayCount, triCount) + partitionCost(rayCount);
}

// The most of a leaf's rayCount rays whose tests fit in `available` loop iterations: all of
// them, or whole passes of one ray per invocation (0 if not even one fits).
uint leafRaysWithin(uint rayCount, uint triCount, uint available) {
    if (leafTestCost(rayCount, triCount) <= available) return rayCount;
    uint passes = available / leafTestCost(kWorkgroupSize, triCount);
    return min(rayCount, passes * kWorkgroupSize);
}

const uint kKeepOverlapping = 5u;  // triangles whose bounds overlap the (widened) cell
// Triangles of a node that overlap its child, which differs from the node's box in one face
// only (along `axis`): the low child's upper face, or the high child's lower face. The node's
// triangles overlap the node's cell on every other face already, so one comparison of
// boundsOverlap's six gives its answer (the cpu backend's one-face filter).
const uint kKeepBelowFace = 14u;  // bounds.lo[axis] <= hi[axis]
const uint kKeepAboveFace = 15u;  // bounds.hi[axis] >= lo[axis]
// For these two, bit 2 of `axis` (kBeyondFace) asks for the complement: the triangles wholly
// beyond the face, which the child does not take (bounds are never NaN: the loader refuses
// them). A second child filters its sibling's triangles so (enterChild), that those it shares
// with the sibling end next to those only it has.
const int kBeyondFace = 4;

bool keepId(uint id, uint rule, vec3 lo, vec3 hi, int axis) {
    if (rule == kKeepOverlapping) return boundsOverlap(TRIANGLE_BOUNDS(id).lo, TRIANGLE_BOUNDS(id).hi, lo, hi);
    int faceAxis = axis & 3;
    bool beyond = (axis & kBeyondFace) != 0;
    if (rule == kKeepBelowFace) return (TRIANGLE_BOUNDS(id).lo[faceAxis] <= hi[faceAxis]) != beyond;
    if (rule == kKeepAboveFace) return (TRIANGLE_BOUNDS(id).hi[faceAxis] >= lo[faceAxis]) != beyond;
    if (rule == kKeepPacketCrossing) return packetMayCrossCell(packets[id], lo, hi);
    if (rule == kKeepDone) return rayDone(id);
    return keepRay(id, rule, lo, hi);
}

// The ids [from, end) of the ray (or triangle) id buffer moved down to `to` (<= from), in order:
// each chunk is read whole before any of its slots is written, and no later chunk reads a slot
// an earlier one wrote (every write lands below the reads so far).
void moveIdsDown(bool triangleIds, uint from, uint end, uint to) {
    if (to == from || from == end) return;  // uniform: nothing moves
    uint lane = gl_LocalInvocationIndex;
    for (uint base = from; base < end; base += kPartitionChunk) {
        uint first = base + lane * kIdsPerInvocation;
        uint ids[kIdsPerInvocation];
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e)
            ids[e] = first + e < end ? (triangleIds ? TRI_IDS(first + e) : RAY_IDS(first + e)) : 0u;
        workgroupSync();
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            if (first + e >= end) continue;
            uint slot = to + (first + e - from);
            if (triangleIds) TRI_IDS(slot) = ids[e];
            else RAY_IDS(slot) = ids[e];
        }
    }
    workgroupSync();
}

// Which ids of an invocation's run (ids[e] at first + e, those at end and past it out of range)
// `rule` keeps: bit e for ids[e]. Each copy of keepId, inlined at every call site, costs
// llvmpipe compile time: unrolled over the run, the four copies made Mesa 25.0.7 compile the
// kernel 1.5x as long (docs/gpu.md, "The kernel's compile time"). Under a loop budget they stay
// unrolled: llvmpipe's loop limiter would count the loop's iterations, which partitionCost
// leaves out.
uint keptOfRun(uint ids[kIdsPerInvocation], uint first, uint end, uint rule, vec3 lo, vec3 hi, int axis) {
    uint keeps = 0u;
    if (kLoopBudget != 0u) {
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e)
            if (first + e < end && keepId(ids[e], rule, lo, hi, axis)) keeps |= 1u << e;
        return keeps;
    }
    [[dont_unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
        uint id = ids[0];
        [[unroll]] for (uint k = 1; k < kIdsPerInvocation; ++k)
            if (e == k) id = ids[k];  // constant indices: the run stays in registers
        if (first + e < end && keepId(id, rule, lo, hi, axis)) keeps |= 1u << e;
    }
    return keeps;
}

// Stable partition of rayIds[begin, end) (or triIds, for kKeepOverlapping; the packet ids in the
// ray id buffer, for kKeepPacketCrossing): the ids `rule` keeps first, in their order, then the
// others in theirs. Kept ids move down in place (never
// onto an unread id); dropped ids wait in the buffer's scratch half and are copied back
// behind them. The ids from certainFrom on (end: none) are kept untested, behind those tested
// and kept. Returns the end of the kept ids.
uint partitionIds(uint begin, uint end, uint certainFrom, uint rule, vec3 lo, vec3 hi, int axis) {
    bool triangleIds = rule == kKeepOverlapping || rule == kKeepBelowFace || rule == kKeepAboveFace;
    uint scratch = (triangleIds ? gTriScratchHalf : (rule == kKeepPacketCrossing ? gPacketCount : gRayScratchHalf)) + begin;
    uint kept = 0, dropped = 0;
    uint lane = gl_LocalInvocationIndex;
    uint tested = end;
    end = certainFrom;
    for (uint base = begin; base < end; base += kPartitionChunk) {
        uint first = base + lane * kIdsPerInvocation;
        uint ids[kIdsPerInvocation];
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            uint index = first + e;
            ids[e] = index < end ? (triangleIds ? TRI_IDS(index) : RAY_IDS(index)) : 0u;
        }
        uint keeps = keptOfRun(ids, first, end, rule, lo, hi, axis);
        uint myKept = bitCount(keeps);
        uint total;
        uint keptBefore = workgroupExclusiveSum(myKept, total);
        // Kept ids move down in place: every id of the chunk must be read before any of the
        // chunk's slots is written (several subgroups already met at a barrier in the sum).
        subgroupSync();
        // Every invocation before this one had a full run of ids (runs fill in order).
        uint droppedBefore = min(lane * kIdsPerInvocation, end - base) - keptBefore;
        uint k = begin + kept + keptBefore, d = scratch + dropped + droppedBefore;
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            if (first + e >= end) continue;
            uint slot = (keeps & (1u << e)) != 0u ? k++ : d++;
            if (triangleIds) TRI_IDS(slot) = ids[e];
            else RAY_IDS(slot) = ids[e];
        }
        kept += total;
        dropped += min(kPartitionChunk, end - base) - total;
    }
    workgroupSync();
    moveIdsDown(triangleIds, certainFrom, tested, begin + kept);
    kept += tested - certainFrom;
    uint keptEnd = begin + kept;
    for (uint base = 0; base < dropped; base += kPartitionChunk) {
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            uint offset = base + lane * kIdsPerInvocation + e;
            if (offset >= dropped) continue;
            if (triangleIds) TRI_IDS(keptEnd + offset) = TRI_IDS(scratch + offset);
            else RAY_IDS(keptEnd + offset) = RAY_IDS(scratch + offset);
        }
    }
    workgroupSync();
    if ((rule == kKeepCrossing || (rule >= kKeepCrossingUp && rule < kKeepPacketCrossing)) && lane == 0)
        atomicAdd(counters.rayBoxTests, end - begin);
    if (rule == kKeepPacketCrossing && lane == 0) atomicAdd(counters.packetBoxTests, end - begin);
    return keptEnd;
}

// The rays [begin, end) that `rule` keeps first; those from certainFrom on kept untested.
uint partitionRaysFrom(uint begin, uint end, uint certainFrom, uint rule, vec3 lo, vec3 hi) {
    uint start = stageClock();
    uint kept = partitionIds(begin, end, certainFrom, rule, lo, hi, 0);
    addStageTicks(DACRT_STAGE_RAY_PARTITIONS, start);
    return kept;
}

uint partitionRays(uint begin, uint end, uint rule, vec3 lo, vec3 hi) {
    return partitionRaysFrom(begin, end, end, rule, lo, hi);
}

// The packet ids [begin, end) that may cross the cell first (a packet level's ray partition);
// those from certainFrom on kept untested.
uint partitionPackets(uint begin, uint end, uint certainFrom, vec3 lo, vec3 hi) {
    uint start = stageClock();
    uint kept = partitionIds(begin, end, certainFrom, kKeepPacketCrossing, lo, hi, 0);
    addStageTicks(DACRT_STAGE_RAY_PARTITIONS, start);
    return kept;
}

// The rays of the packets whose ids are at [begin, end) that have no final hit yet, copied to
// the ray ids from `to` in packet order; returns the end of the copies. A flush's gathering
// counts with the ray partitions, whose work it does.
uint gatherPacketRays(uint begin, uint end, uint to) {
    uint start = stageClock();
    uint lane = gl_LocalInvocationIndex;
    uint count = 0;
    for (uint p = begin; p < end; ++p) {
        PacketBounds packet = packets[RAY_IDS(p)];
        for (uint base = packet.rayBegin; base < packet.rayEnd; base += kPartitionChunk) {
            uint first = base + lane * kIdsPerInvocation;
            uint ids[kIdsPerInvocation];
            bool live[kIdsPerInvocation];
            uint mine = 0;
            [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
                bool inRange = first + e < packet.rayEnd;
                ids[e] = inRange ? RAY_IDS(gPacketRaysAt + first + e) : 0u;
                live[e] = inRange && !rayDone(ids[e]);
                mine += live[e] ? 1u : 0u;
            }
            uint total;
            uint slot = to + count + workgroupExclusiveSum(mine, total);
            [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
                if (!live[e]) continue;
                RAY_IDS(slot) = ids[e];  // RAY_IDS reads its index twice: no increment inside
                ++slot;
            }
            count += total;
        }
    }
    workgroupSync();
    addStageTicks(DACRT_STAGE_RAY_PARTITIONS, start);
    return to + count;
}

// Flags the rays whose ids are at [begin, end) as having their final hit.
void markRaysDone(uint begin, uint end) {
    for (uint k = begin + gl_LocalInvocationIndex; k < end; k += kWorkgroupSize) {
        uint id = RAY_IDS(k);
        RAY_IDS(gDoneFlagsAt + id) = 1u;
    }
    workgroupSync();
}

uint partitionTriangles(uint begin, uint end, vec3 lo, vec3 hi) {
    uint start = stageClock();
    uint kept = partitionIds(begin, end, end, kKeepOverlapping, lo, hi, 0);
    addStageTicks(DACRT_STAGE_TRIANGLE_PARTITIONS, start);
    return kept;
}

// The node's triangles [begin, end) that overlap its child (the widened cell lo, hi), which
// moved one face of the node's box along `axis`: the upper face (the low child) or the lower
// one (the high child). beyond: those wholly beyond that face first instead, the triangles
// the child does not take.
uint partitionTrianglesAtFace(uint begin, uint end, vec3 lo, vec3 hi, int axis, bool highChild, bool beyond) {
    uint start = stageClock();
    int face = axis | (beyond ? kBeyondFace : 0);
    uint kept = highChild ? partitionIds(begin, end, end, kKeepAboveFace, lo, hi, face)
                          : partitionIds(begin, end, end, kKeepBelowFace, lo, hi, face);
    addStageTicks(DACRT_STAGE_TRIANGLE_PARTITIONS, start);
    return kept;
}

// A float's bits as a uint whose unsigned order is the float's order (negatives reversed), so
// that shared uint atomics take a float minimum or maximum across subgroups.
uint orderedKey(float x) {
    uint bits = floatBitsToUint(x);
    return (bits & 0x80000000u) != 0u ? ~bits : bits | 0x80000000u;
}

float orderedFloat(uint key) {
    return uintBitsToFloat((key & 0x80000000u) != 0u ? key & 0x7FFFFFFFu : ~key);
}

// The box of the bounds of triangles triIds[begin, end): their exact minimum and maximum (a
// minimum or a maximum rounds nothing, so the order of the reduction changes no bit but
// the sign of a zero). Subgroup reductions, then one shared atomic per subgroup and axis.
void triangleBoundsBox(uint begin, uint end, out vec3 lo, out vec3 hi) {
    uint start = stageClock();
    vec3 myLo = vec3(kNoHitT), myHi = vec3(-kNoHitT);
    for (uint base = begin; base < end; base += kPartitionChunk) {
        uint first = base + gl_LocalInvocationIndex * kIdsPerInvocation;
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            if (first + e >= end) continue;
            uint id = TRI_IDS(first + e);
            myLo = min(myLo, TRIANGLE_BOUNDS(id).lo);
            myHi = max(myHi, TRIANGLE_BOUNDS(id).hi);
        }
    }
    lo = subgroupMin(myLo);
    hi = subgroupMax(myHi);
    if (!(kLockstepSubgroups || gl_NumSubgroups == 1)) {
        if (gl_LocalInvocationIndex == 0) {
            [[unroll]] for (int a = 0; a < 3; ++a) {
                sBoxKeys[a] = 0xFFFFFFFFu;
                sBoxKeys[3 + a] = 0u;
            }
        }
        memoryBarrierShared();
        barrier();
        if (subgroupElect()) {
            [[unroll]] for (int a = 0; a < 3; ++a) {
                atomicMin(sBoxKeys[a], orderedKey(lo[a]));
                atomicMax(sBoxKeys[3 + a], orderedKey(hi[a]));
            }
        }
        memoryBarrierShared();
        barrier();
        [[unroll]] for (int a = 0; a < 3; ++a) {
            lo[a] = orderedFloat(sBoxKeys[a]);
            hi[a] = orderedFloat(sBoxKeys[3 + a]);
        }
        barrier();  // sBoxKeys is reused by the next call
    }
    addStageTicks(DACRT_STAGE_TRIANGLE_PARTITIONS, start);
}

// Invocations that share one ray in a leaf with rayCount rays: a power of two, so that one
// ray's lanes are a run of one subgroup that a butterfly of shuffles reduces.
uint leafLanesPerRay(uint rayCount) {
    return 1u << findMSB(max(1u, gl_SubgroupSize / max(rayCount, 1u)));
}

// The fields of a ray that the triangle test reads: origin, tmin, axes and shear.
Ray leafRay(uint id) {
    Ray ray = rayStart(id);
    ray.axes = RAYS(id).axes;
    ray.shear = RAYS(id).shear;
    return ray;
}

// One ray against one triangle: the better hit under the tie rule kept (the host's testTriangle).
void testTriangle(Ray ray, uint prim, vec3 v0, vec3 v1, vec3 v2, bool cullBackFace, inout Hit best) {
    TriangleHit h = intersectWatertight(ray, v0, v1, v2, cullBackFace);
    if (h.hit && h.t > ray.tmin && hitPrecedes(h.t, prim, best.t, best.prim)) {
        best.t = h.t;
        best.prim = prim;
        best.u = h.u;
        best.v = h.v;
    }
}

// Lane k's tile triangle, shuffled to every lane (in uniform control flow), tested where test.
void testTileTriangle(uint k, uint myPrim, Triangle mine, Ray ray, bool test, inout Hit best) {
    uint prim = subgroupShuffle(myPrim, k);
    vec3 v0 = subgroupShuffle(mine.v0, k);
    vec3 v1 = subgroupShuffle(mine.v1, k);
    vec3 v2 = subgroupShuffle(mine.v2, k);
    bool cullBackFace = subgroupShuffle(mine.cullBackFace, k) != 0u;
    if (test) testTriangle(ray, prim, v0, v1, v2, cullBackFace, best);
}

// The subgroup's active rays as one packet (the host's addToPacketBounds over them): where
// rays share their start, a triangle whose bounds, widened by twice the filter margin, the
// packet cannot cross is a triangle none of them can hit (docs/correctness.md, "Leaf groups").
PacketBounds subgroupRaysBounds(bool rayActive, uint id) {
    vec3 invDir = RAYS(id).invDir;
    PacketBounds p;
    uint unbounded = 0u;
    [[unroll]] for (int a = 0; a < 3; ++a) {
        // Not finite written as a comparison, as the compiler may assume no infinity in
        // isinf(); a NaN the compiler's reordering of it could let through cannot occur
        // (makeRay's invDir is 1 / dir of a finite, nonzero component, or 0).
        if (rayActive && (invDir[a] == 0.0 || !(abs(invDir[a]) <= 3.4028234e38))) unbounded |= 1u << uint(a);
        p.invLo[a] = subgroupMin(rayActive ? invDir[a] : kNoHitT);
        p.invHi[a] = subgroupMax(rayActive ? invDir[a] : -kNoHitT);
    }
    p.unboundedAxes = subgroupOr(unbounded);
    return p;
}

// The subgroup's lanes where the condition holds, a bit each (lane l: bit l & 31 of word
// l >> 5): subgroupBallot's answer from the arithmetic operations the device already offers,
// for subgroups of up to 128 lanes.
uvec4 lanesWhere(bool condition) {
    uint lane = gl_SubgroupInvocationID;
    uvec4 bits = uvec4(0u);
    if (condition) bits[lane >> 5u] = 1u << (lane & 31u);
    return subgroupOr(bits);
}

// The lowest lane of a non-empty lanesWhere answer (Vulkan's subgroups have at most 128
// lanes). No loop: llvmpipe's loop limiter counts every iteration (leafTestCost).
uint firstLane(uvec4 lanes) {
    return lanes.x != 0u   ? uint(findLSB(lanes.x))
           : lanes.y != 0u ? 32u + uint(findLSB(lanes.y))
           : lanes.z != 0u ? 64u + uint(findLSB(lanes.z))
                           : 96u + uint(findLSB(lanes.w));
}

// Whether a triangle's bounds widened by twice the filter margin may be crossed by a ray of
// the packet.
bool packetMayCrossTriangle(PacketBounds p, vec3 v0, vec3 v1, vec3 v2) {
    precise float widening = 2.0 * gMargin;
    precise vec3 lo = min(min(v0, v1), v2) - vec3(widening);
    precise vec3 hi = max(max(v0, v1), v2) + vec3(widening);
    return packetMayCrossCell(p, lo, hi);
}

// Rays rayIds[rayBegin, rayEnd) of a leaf against its triangles, updating their best hits.
// A large leaf may take several calls (slices) over consecutive ray ranges. Each subgroup
// works alone: every lane loads one triangle of a subgroup-sized tile and the tile reaches
// the other lanes by shuffles, not through shared memory (llvmpipe reads and writes memory
// one invocation at a time, but shuffles in registers). With fewer rays than lanes each ray
// gets `lanes` lanes that split the tile; a butterfly then gives all of them the best hit.
// Where rays share their start and each has its own lane, the subgroup's rays test only the
// tile's triangles their packet may reach (subgroupRaysBounds): no more loop iterations than
// the whole tile, so leafTestCost still bounds them.
void leafTests(uint rayBegin, uint rayEnd, uint triBegin, uint triEnd) {
    uint start = stageClock();
    uint lane = gl_SubgroupInvocationID;
    uint rayCount = rayEnd - rayBegin;
    uint lanes = leafLanesPerRay(rayCount);
    uint slot = lane & (lanes - 1u);
    uint raysPerSubgroup = gl_SubgroupSize / lanes;
    uint raysPerPass = gl_NumSubgroups * raysPerSubgroup;
    uint myRay = gl_SubgroupID * raysPerSubgroup + lane / lanes;
    if (gl_LocalInvocationIndex == 0) atomicAdd(counters.rayTriangleTests, rayCount * (triEnd - triBegin));
    for (uint first = rayBegin; first < rayEnd; first += raysPerPass) {
        uint index = first + myRay;
        bool rayActive = index < rayEnd;
        uint id = rayActive ? RAY_IDS(index) : 0u;
        Ray ray = leafRay(id);
        Hit best = liveRayHit(id);
        bool grouped = kSharedStart && lanes == 1u;
        PacketBounds group;
        if (grouped) group = subgroupRaysBounds(rayActive, id);
        for (uint tile = triBegin; tile < triEnd; tile += gl_SubgroupSize) {
            uint tileSize = min(gl_SubgroupSize, triEnd - tile);
            uint myPrim = lane < tileSize ? TRI_IDS(tile + lane) : 0u;
            Triangle mine = TRIANGLES(myPrim);
            if (grouped) {
                uvec4 kept = lanesWhere(lane < tileSize && packetMayCrossTriangle(group, mine.v0, mine.v1, mine.v2));
                uint keptCount = bitCount(kept.x) + bitCount(kept.y) + bitCount(kept.z) + bitCount(kept.w);
                for (uint j = 0; j < keptCount; ++j) {  // uniform: kept is the subgroup's
                    uint k = firstLane(kept);
                    kept[k >> 5u] &= ~(1u << (k & 31u));
                    testTileTriangle(k, myPrim, mine, ray, rayActive, best);
                }
                continue;
            }
            for (uint j = 0; j < tileSize; j += lanes) {  // uniform: every lane shuffles
                uint k = j + slot;
                testTileTriangle(k, myPrim, mine, ray, rayActive && k < tileSize, best);
            }
        }
        // hitPrecedes is a total order on (t, prim), so the butterfly's order of comparisons
        // gives the sequential answer.
        for (uint mask = 1u; mask < lanes; mask <<= 1u) {
            Hit other;
            other.t = subgroupShuffleXor(best.t, mask);
            other.prim = subgroupShuffleXor(best.prim, mask);
            other.u = subgroupShuffleXor(best.u, mask);
            other.v = subgroupShuffleXor(best.v, mask);
            if (hitPrecedes(other.t, other.prim, best.t, best.prim)) best = other;
        }
        if (rayActive && slot == 0u) HITS(id) = best;
    }
    workgroupSync();
    addStageTicks(DACRT_STAGE_LEAF_TESTS, start);
}

// After a leaf's tests: the rays whose best hit ends them inside the leaf box move to the
// front and the returned `terminated` is past them.
uint finishLeaf(vec3 lo, vec3 hi, uint terminated, uint rayEnd) {
    if (gl_LocalInvocationIndex == 0) atomicAdd(counters.leaves, 1u);
    return partitionRays(terminated, rayEnd, kKeepFinished, lo, hi);
}

// A whole leaf at once: every live ray against every triangle, then finishLeaf.
uint leaf(vec3 lo, vec3 hi, uint terminated, uint rayEnd, uint triBegin, uint triEnd) {
    leafTests(terminated, rayEnd, triBegin, triEnd);
    return finishLeaf(lo, hi, terminated, rayEnd);
}

#endif
