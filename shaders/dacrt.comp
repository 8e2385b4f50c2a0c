#version 450
// One DACRT work item per workgroup: the live rays of one region against the triangles of
// one region (Step 1: its own), depth first on an explicit stack in shared memory.
//
// A work item may take several dispatches (slices): with a loop budget (llvmpipe's loop
// limiter), a slice stops before a step that would overrun it and saves its node and stack;
// the next dispatch over the same work item resumes there. A work item also waits (exits at
// once) until every earlier work item on its rays and on its triangles has finished, so a
// dispatch may hold work items of several rounds without two of them sharing a range.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require

#define IN(T) in T
#include "layout.h"
#include "predicates.glsl"
#include "dacrt_bindings.glsl"
#include "dacrt_workgroup.glsl"

layout(push_constant) uniform Push { DacrtPush push; };

const uint kPhaseNew = 0u;
const uint kPhaseRunning = 1u;
const uint kPhaseFinished = 2u;

int longestAxis(vec3 lo, vec3 hi) {
    vec3 e = hi - lo;
    return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
}

// Loop iterations a step (split, pop, leaf slice) costs besides its partitions and tests.
// Measured with the loop probe (docs/stability.md): with 8 a slice of tiny nodes, as with
// --ray-limit 1 --tri-limit 1, overran its estimate by up to 20%; with 16 none did.
const uint kStepOverhead = 16u;

bool overBudget(uint spent, uint cost) {
    return kLoopBudget != 0u && spent + cost > kLoopBudget;
}

void main() {
    gMargin = push.margin;
    gRayOrigin = push.rayOrigin;
    gRayTmin = push.rayTmin;
    gAxis = push.axis;
    gRayScratchHalf = push.rayScratchHalf;
    gTriScratchHalf = push.triScratchHalf;
    uint lane = gl_LocalInvocationIndex;
    uint itemIndex = push.firstWorkItem + gl_WorkGroupID.x;
    WorkItem item = workItems[itemIndex];
    TraversalState state = states[itemIndex];
    if (state.phase == kPhaseFinished) return;
    // Earlier work items may finish during this very dispatch: one invocation reads the
    // counters and the whole workgroup follows its answer, so control flow stays uniform.
    if (lane == 0)
        sReady = atomicAdd(regions[item.rayRegion].rayItemsDone, 0u) == item.raySeq &&
                 atomicAdd(regions[item.triRegion].triItemsDone, 0u) == item.triSeq;
    memoryBarrierShared();
    barrier();
    if (!sReady) {
        if (lane == 0) atomicAdd(counters.notReady, 1u);
        return;
    }
    memoryBarrierBuffer();  // see the finished work items' writes (they barrier before counting)
    if (lane == 0) atomicAdd(counters.slices, 1u);
    uint terminated = regions[item.rayRegion].terminated;
    uint rayEnd = regions[item.rayRegion].rayEnd;
    vec3 rootLo = regions[item.triRegion].lo;
    vec3 rootHi = regions[item.triRegion].hi;
    vec3 margin = vec3(gMargin);
    uint retireCost = partitionCost(rayEnd - terminated) + 4u;  // the final partition and the probe
    uint spent = 0;

    vec3 lo = state.lo, hi = state.hi;
    uint nodeRayEnd = state.nodeRayEnd, triBegin = state.triBegin, triEnd = state.triEnd, depth = state.depth;
    uint stackSize = state.stackSize, stalls = state.stalls, leafNext = state.leafNext;
    if (state.phase == kPhaseNew && terminated >= rayEnd) {  // nothing to trace: finish at once
        if (lane == 0) {
            atomicAdd(counters.workItemsEmpty, 1u);
            states[itemIndex].phase = kPhaseFinished;
            atomicAdd(counters.itemsFinished, 1u);
            memoryBarrierBuffer();
            atomicAdd(regions[item.rayRegion].rayItemsDone, 1u);
            atomicAdd(regions[item.triRegion].triItemsDone, 1u);
        }
        return;
    }
    if (state.phase == kPhaseNew) {
        if (lane == 0) atomicAdd(counters.workItemsRun, 1u);
        // Root: the rays that may cross this region go first.
        spent = partitionCost(rayEnd - terminated);
        if (overBudget(spent, retireCost)) {
            if (lane == 0) atomicAdd(counters.tooLarge, 1u);
            return;
        }
        nodeRayEnd = partitionRays(terminated, rayEnd, kKeepCrossing, rootLo - margin, rootHi + margin);
        lo = rootLo;
        hi = rootHi;
        triBegin = regions[item.triRegion].triBegin;
        triEnd = regions[item.triRegion].triEnd;
        depth = 0;
        stackSize = 0;
        stalls = 0;
        leafNext = 0;
    } else {
        for (uint i = lane; i < stackSize; i += kWorkgroupSize) sStack[i] = stacks[itemIndex * (kMaxDepth + 1u) + i];
        spent = stackSize / kWorkgroupSize + 1u;
        workgroupSync();
    }

    bool finished = false;
    bool progressed = state.phase == kPhaseNew;  // the root partition ran
    for (;;) {
        if (terminated < nodeRayEnd && triBegin < triEnd) {
            uint rayCount = nodeRayEnd - terminated, triCount = triEnd - triBegin;
            int axis = longestAxis(lo, hi);
            float split = 0.5 * (lo[axis] + hi[axis]);
            bool canSplit = depth < kMaxDepth && split > lo[axis] && split < hi[axis] &&
                            stalls < DACRT_MAX_STALLED_SPLITS;
            bool isLeaf = rayCount < kRayLimit || triCount < kTriLimit || !canSplit || leafNext != 0u;
            // Under a loop budget a leaf too large for half a slice splits further instead
            // while splitting still separates something: another tree, the same hits (every
            // tree gives brute force's answer). A leaf that must stay one runs in slices.
            if (isLeaf && canSplit && leafNext == 0u && kLoopBudget != 0u && leafCost(rayCount, triCount) > kLoopBudget / 2u)
                isLeaf = false;
            if (isLeaf) {
                uint from = leafNext != 0u ? leafNext : terminated;
                uint finish = partitionCost(rayCount);
                uint take = nodeRayEnd - from;
                if (kLoopBudget != 0u) {
                    uint reserved = spent + retireCost + finish;
                    reserved += kStepOverhead;
                    take = reserved < kLoopBudget ? leafRaysWithin(take, triCount, kLoopBudget - reserved) : 0u;
                    if (take == 0u) break;
                }
                leafTests(from, from + take, triBegin, triEnd);
                spent += leafTestCost(take, triCount) + kStepOverhead;
                progressed = true;
                leafNext = from + take;
                if (leafNext == nodeRayEnd) {
                    terminated = finishLeaf(lo, hi, terminated, nodeRayEnd);
                    spent += finish;
                    nodeRayEnd = terminated;
                    leafNext = 0u;
                }
                continue;
            }
            uint cost = partitionCost(rayCount) + partitionCost(triCount) + kStepOverhead;
            if (overBudget(spent, cost + retireCost)) break;
            spent += cost;
            progressed = true;
            {
                // Front to back: the child on the rays' origin side first; the other waits on
                // the stack with this node's ranges, which it filters again later.
                vec3 lowHi = hi, highLo = lo;
                lowHi[axis] = split;
                highLo[axis] = split;
                bool lowFirst = gRayOrigin[axis] <= split;
                vec3 nearLo = lowFirst ? lo : highLo, nearHi = lowFirst ? lowHi : hi;
                if (lane == 0) {
                    StackEntry far;
                    far.lo = lowFirst ? highLo : lo;
                    far.hi = lowFirst ? hi : lowHi;
                    far.rayEnd = nodeRayEnd;
                    far.triBegin = triBegin;
                    far.triEnd = triEnd;
                    far.depth = depth + 1u;
                    far.stalls = stalls;
                    sStack[stackSize] = far;
                }
                ++stackSize;
                uint childRayEnd = partitionRays(terminated, nodeRayEnd, kKeepCrossing, nearLo - margin, nearHi + margin);
                uint childTriEnd = triEnd;
                if (childRayEnd > terminated)
                    childTriEnd = partitionTriangles(triBegin, triEnd, nearLo - margin, nearHi + margin);
                stalls = childRayEnd == nodeRayEnd && childTriEnd == triEnd ? stalls + 1u : 0u;
                triEnd = childTriEnd;
                lo = nearLo;
                hi = nearHi;
                nodeRayEnd = childRayEnd;
                ++depth;
            }
            continue;
        }
        if (stackSize == 0) {
            finished = true;
            break;
        }
        workgroupSync();
        StackEntry far = sStack[stackSize - 1u];
        uint cost = partitionCost(far.rayEnd - terminated) + partitionCost(far.triEnd - far.triBegin) + kStepOverhead;
        if (overBudget(spent, cost + retireCost)) break;
        spent += cost;
        progressed = true;
        --stackSize;
        workgroupSync();  // the slot may be written again before everyone has read it
        lo = far.lo;
        hi = far.hi;
        nodeRayEnd = partitionRays(terminated, far.rayEnd, kKeepCrossing, lo - margin, hi + margin);
        triBegin = far.triBegin;
        triEnd = nodeRayEnd > terminated ? partitionTriangles(far.triBegin, far.triEnd, lo - margin, hi + margin)
                                         : far.triBegin;
        depth = far.depth;
        stalls = nodeRayEnd == far.rayEnd && triEnd == far.triEnd ? far.stalls + 1u : 0u;
    }

    if (!finished) {
        // Out of budget: save the node and the stack; a later dispatch resumes here.
        if (!progressed && lane == 0) atomicAdd(counters.tooLarge, 1u);
        workgroupSync();
        for (uint i = lane; i < stackSize; i += kWorkgroupSize) stacks[itemIndex * (kMaxDepth + 1u) + i] = sStack[i];
        bool cutShort = loopLimiterFired(push.loopProbe);
        if (lane == 0) {
            TraversalState saved;
            saved.lo = lo;
            saved.hi = hi;
            saved.phase = kPhaseRunning;
            saved.nodeRayEnd = nodeRayEnd;
            saved.triBegin = triBegin;
            saved.triEnd = triEnd;
            saved.depth = depth;
            saved.stackSize = stackSize;
            saved.stalls = stalls;
            saved.leafNext = leafNext;
            states[itemIndex] = saved;
            regions[item.rayRegion].terminated = terminated;
            if (cutShort) atomicAdd(counters.loopLimitHits, 1u);
        }
        return;
    }

    // Rays no later work item can change are finished here (see RetireRule on the CPU side).
    uint rule = item.retire == 0u ? kKeepStill : (item.retire == 1u ? kKeepStuckHigh : kKeepStuckLow);
    uint before = terminated;
    terminated = partitionRays(terminated, rayEnd, rule, rootLo - margin, rootHi + margin);
    bool cutShort = loopLimiterFired(push.loopProbe);
    if (lane == 0) {
        atomicAdd(counters.raysRetired, terminated - before);
        regions[item.rayRegion].terminated = terminated;
        states[itemIndex].phase = kPhaseFinished;
        if (cutShort) atomicAdd(counters.loopLimitHits, 1u);
        atomicAdd(counters.itemsFinished, 1u);
        memoryBarrierBuffer();
        atomicAdd(regions[item.rayRegion].rayItemsDone, 1u);
        atomicAdd(regions[item.triRegion].triItemsDone, 1u);
    }
}
