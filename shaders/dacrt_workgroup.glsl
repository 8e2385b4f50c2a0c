// Workgroup-wide building blocks of the DACRT kernel: synchronisation, prefix sums, stable
// partitions of the id arrays, and leaves. Every function here is called in uniform control
// flow by the whole workgroup and returns the same value to every invocation.
#ifndef DACRT_WORKGROUP_GLSL
#define DACRT_WORKGROUP_GLSL

// Makes buffer and shared writes of every invocation visible to the whole workgroup. A
// workgroup of one subgroup needs only a subgroup barrier.
void workgroupSync() {
    if (gl_NumSubgroups == 1) {
        subgroupMemoryBarrierBuffer();
        subgroupMemoryBarrierShared();
        subgroupBarrier();
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
    if (gl_NumSubgroups == 1) {
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

bool keepRay(uint id, uint rule, vec3 lo, vec3 hi) {
    Ray ray = rays[id];
    float bestT = hits[id].t;
    if (rule == kKeepCrossing) return rayMayCrossCell(ray, lo, hi, bestT);
    if (rule == kKeepFinished) return hits[id].prim != kMissPrim && hitEndsInBox(ray, lo, hi, bestT);
    float d = ray.dir[gAxis];
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

// ... the ray/triangle tests of rayCount rays against triCount triangles (leafTests) ...
uint leafTestCost(uint rayCount, uint triCount) {
    uint lanes = max(1u, kWorkgroupSize / max(rayCount, 1u));
    uint raysPerPass = kWorkgroupSize / lanes;
    uint passes = (rayCount + raysPerPass - 1u) / raysPerPass;
    uint tiles = (triCount + kWorkgroupSize - 1u) / kWorkgroupSize;
    uint perTile = 2u + (kWorkgroupSize + lanes - 1u) / lanes;
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

bool keepId(uint id, uint rule, vec3 lo, vec3 hi) {
    if (rule == kKeepOverlapping) return boundsOverlap(triangleBounds[id].lo, triangleBounds[id].hi, lo, hi);
    return keepRay(id, rule, lo, hi);
}

// Stable partition of rayIds[begin, end) (or triIds, for kKeepOverlapping): the ids `rule`
// keeps first, in their order, then the others in theirs. Out of place through the two
// halves of the matching scratch buffer, then copied back. Returns the end of the kept ids.
uint partitionIds(uint begin, uint end, uint rule, vec3 lo, vec3 hi) {
    bool triangleIds = rule == kKeepOverlapping;
    uint secondHalf = triangleIds ? gTriScratchHalf : gRayScratchHalf;
    uint kept = 0, dropped = 0;
    uint lane = gl_LocalInvocationIndex;
    for (uint base = begin; base < end; base += kPartitionChunk) {
        uint first = base + lane * kIdsPerInvocation;
        uint ids[kIdsPerInvocation];
        bool keeps[kIdsPerInvocation];
        uint myKept = 0;
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            uint index = first + e;
            bool inRange = index < end;
            ids[e] = inRange ? (triangleIds ? triIds[index] : rayIds[index]) : 0u;
            keeps[e] = inRange && keepId(ids[e], rule, lo, hi);
            myKept += keeps[e] ? 1u : 0u;
        }
        uint total;
        uint keptBefore = workgroupExclusiveSum(myKept, total);
        // Every invocation before this one had a full run of ids (runs fill in order).
        uint droppedBefore = min(lane * kIdsPerInvocation, end - base) - keptBefore;
        uint k = begin + kept + keptBefore, d = secondHalf + begin + dropped + droppedBefore;
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            if (first + e >= end) continue;
            uint slot = keeps[e] ? k++ : d++;
            if (triangleIds) triScratch[slot] = ids[e];
            else rayScratch[slot] = ids[e];
        }
        kept += total;
        dropped += min(kPartitionChunk, end - base) - total;
    }
    workgroupSync();
    for (uint base = begin; base < end; base += kPartitionChunk) {
        [[unroll]] for (uint e = 0; e < kIdsPerInvocation; ++e) {
            uint index = base + lane * kIdsPerInvocation + e;
            if (index >= end) continue;
            uint offset = index - begin;
            uint from = offset < kept ? index : secondHalf + begin + offset - kept;
            if (triangleIds) triIds[index] = triScratch[from];
            else rayIds[index] = rayScratch[from];
        }
    }
    workgroupSync();
    if (rule == kKeepCrossing && lane == 0) atomicAdd(counters.rayBoxTests, end - begin);
    return begin + kept;
}

uint partitionRays(uint begin, uint end, uint rule, vec3 lo, vec3 hi) {
    return partitionIds(begin, end, rule, lo, hi);
}

uint partitionTriangles(uint begin, uint end, vec3 lo, vec3 hi) {
    return partitionIds(begin, end, kKeepOverlapping, lo, hi);
}

// Rays rayIds[rayBegin, rayEnd) of a leaf against its triangles, updating their best hits.
// A large leaf may take several calls (slices) over consecutive ray ranges. Every
// invocation stays busy: with fewer rays than invocations each ray gets `lanes`
// invocations that split the triangles and reduce their bests; triangles are staged in
// shared memory one workgroup-sized tile at a time.
void leafTests(uint rayBegin, uint rayEnd, uint triBegin, uint triEnd) {
    uint lane = gl_LocalInvocationIndex;
    uint rayCount = rayEnd - rayBegin;
    uint lanes = max(1u, kWorkgroupSize / rayCount);
    uint raysPerPass = kWorkgroupSize / lanes;
    uint myRay = lane / lanes;
    uint mySlot = lane % lanes;
    if (lane == 0) atomicAdd(counters.rayTriangleTests, rayCount * (triEnd - triBegin));
    for (uint first = rayBegin; first < rayEnd; first += raysPerPass) {
        uint index = first + myRay;
        bool rayActive = myRay < raysPerPass && index < rayEnd;
        uint id = rayActive ? rayIds[index] : 0u;
        Ray ray = rays[id];
        Hit best = hits[id];
        for (uint tile = triBegin; tile < triEnd; tile += kWorkgroupSize) {
            workgroupSync();
            if (tile + lane < triEnd) {
                uint prim = triIds[tile + lane];
                sPrims[lane] = prim;
                sTriangles[lane] = triangles[prim];
            }
            workgroupSync();
            uint tileSize = min(kWorkgroupSize, triEnd - tile);
            if (rayActive) {
                for (uint k = mySlot; k < tileSize; k += lanes) {
                    TriangleHit h = intersectWatertight(ray, sTriangles[k].v0, sTriangles[k].v1, sTriangles[k].v2);
                    if (h.hit && h.t > ray.tmin && hitPrecedes(h.t, sPrims[k], best.t, best.prim)) {
                        best.t = h.t;
                        best.prim = sPrims[k];
                        best.u = h.u;
                        best.v = h.v;
                    }
                }
            }
        }
        if (lanes > 1) {
            sBestT[lane] = best.t;
            sBestPrim[lane] = best.prim;
            sBestU[lane] = best.u;
            sBestV[lane] = best.v;
            workgroupSync();
            if (rayActive && mySlot == 0) {
                for (uint k = lane + 1; k < lane + lanes; ++k) {
                    if (hitPrecedes(sBestT[k], sBestPrim[k], best.t, best.prim)) {
                        best.t = sBestT[k];
                        best.prim = sBestPrim[k];
                        best.u = sBestU[k];
                        best.v = sBestV[k];
                    }
                }
            }
        }
        if (rayActive && mySlot == 0) hits[id] = best;
        workgroupSync();
    }
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
