#version 450
// One DACRT work item per workgroup: the live rays of one region against the triangles of
// one region (Step 1: its own), depth first on an explicit stack in shared memory.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#define IN(T) in T
#include "layout.h"
#include "predicates.glsl"
#include "dacrt_bindings.glsl"
#include "dacrt_workgroup.glsl"

layout(push_constant) uniform Push { DacrtPush push; };

int longestAxis(vec3 lo, vec3 hi) {
    vec3 e = hi - lo;
    return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
}

void main() {
    gMargin = push.margin;
    gRayOrigin = push.rayOrigin;
    gAxis = push.axis;
    gRayScratchHalf = push.rayScratchHalf;
    gTriScratchHalf = push.triScratchHalf;
    uint lane = gl_LocalInvocationIndex;
    WorkItem item = workItems[push.firstWorkItem + gl_WorkGroupID.x];
    uint terminated = regions[item.rayRegion].terminated;
    uint rayEnd = regions[item.rayRegion].rayEnd;
    if (terminated >= rayEnd) {  // nothing left to trace: the cheapest possible work item
        if (lane == 0) atomicAdd(counters.workItemsEmpty, 1u);
        return;
    }
    if (lane == 0) atomicAdd(counters.workItemsRun, 1u);
    vec3 rootLo = regions[item.triRegion].lo;
    vec3 rootHi = regions[item.triRegion].hi;
    vec3 margin = vec3(gMargin);

    // Root: the rays that may cross this region go first.
    uint crossing = partitionRays(terminated, rayEnd, kKeepCrossing, rootLo - margin, rootHi + margin);
    vec3 lo = rootLo, hi = rootHi;
    uint nodeRayEnd = crossing;
    uint triBegin = regions[item.triRegion].triBegin, triEnd = regions[item.triRegion].triEnd;
    uint depth = 0;
    uint stackSize = 0;
    for (;;) {
        bool pop = true;
        if (terminated < nodeRayEnd && triBegin < triEnd) {
            uint rayCount = nodeRayEnd - terminated, triCount = triEnd - triBegin;
            int axis = longestAxis(lo, hi);
            float split = 0.5 * (lo[axis] + hi[axis]);
            if (rayCount < kRayLimit || triCount < kTriLimit || depth >= kMaxDepth ||
                !(split > lo[axis] && split < hi[axis])) {
                terminated = leaf(lo, hi, terminated, nodeRayEnd, triBegin, triEnd);
            } else {
                // Front to back: the child on the rays' origin side first; the other waits on
                // the stack with this node's ranges, which it filters again later.
                vec3 lowHi = hi, highLo = lo;
                lowHi[axis] = split;
                highLo[axis] = split;
                bool lowFirst = gRayOrigin[axis] <= split;
                vec3 nearLo = lo, nearHi = lowFirst ? lowHi : hi;
                if (!lowFirst) nearLo = highLo;
                if (lane == 0) {
                    sStackLo[stackSize] = lowFirst ? highLo : lo;
                    sStackHi[stackSize] = lowFirst ? hi : lowHi;
                    sStackRanges[stackSize] = uvec4(nodeRayEnd, triBegin, triEnd, depth + 1);
                }
                ++stackSize;
                uint childRayEnd = partitionRays(terminated, nodeRayEnd, kKeepCrossing, nearLo - margin, nearHi + margin);
                if (childRayEnd > terminated) {
                    triEnd = partitionTriangles(triBegin, triEnd, nearLo - margin, nearHi + margin);
                    lo = nearLo;
                    hi = nearHi;
                    nodeRayEnd = childRayEnd;
                    ++depth;
                    pop = false;
                }
            }
        }
        if (!pop) continue;
        if (stackSize == 0) break;
        --stackSize;
        workgroupSync();
        lo = sStackLo[stackSize];
        hi = sStackHi[stackSize];
        uvec4 ranges = sStackRanges[stackSize];
        workgroupSync();  // the slot may be written again before everyone has read it
        nodeRayEnd = partitionRays(terminated, ranges.x, kKeepCrossing, lo - margin, hi + margin);
        triBegin = ranges.y;
        triEnd = nodeRayEnd > terminated ? partitionTriangles(ranges.y, ranges.z, lo - margin, hi + margin) : ranges.y;
        depth = ranges.w;
    }

    // Rays no later work item can change are finished here (see RetireRule on the CPU side).
    uint rule = item.retire == 0u ? kKeepStill : (item.retire == 1u ? kKeepStuckHigh : kKeepStuckLow);
    uint before = terminated;
    terminated = partitionRays(terminated, rayEnd, rule, rootLo - margin, rootHi + margin);
    bool cutShort = loopLimiterFired(push.loopProbe);
    if (lane == 0) {
        atomicAdd(counters.raysRetired, terminated - before);
        regions[item.rayRegion].terminated = terminated;
        if (cutShort) atomicAdd(counters.loopLimitHits, 1u);
    }
}
