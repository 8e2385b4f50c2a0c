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
#ifdef DACRT_STAGE_CLOCKS
#extension GL_ARB_shader_clock : require
#endif

#define IN(T) in T
#include "layout.h"
#include "predicates.glsl"
#include "dacrt_bindings.glsl"
#include "dacrt_workgroup.glsl"
#include "leaf_rule.glsl"

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

// The running work item: its node, its stack size and the slice's loop budget spent. Saved to
// `states` (and the stack to `stacks`) when a slice runs out of budget.
struct Slice {
    vec3 lo;
    vec3 hi;
    uint terminated;   // rays [rayBegin, terminated) of the ray region have their final hit
    uint nodeRayEnd;
    uint triBegin;
    uint triEnd;
    uint depth;
    uint stackSize;
    uint stalls;
    uint leafNext;     // a leaf running in slices: its next ray, else 0
    uint spent;        // loop iterations this slice has used
    uint costBefore;   // loop iterations the earlier slices of the work item used
    uint stackSlot;    // TraversalState::stackSlot
    bool progressed;   // this slice did some work (else the work item cannot fit a slice)
    // With packets: whether the node is one of packets, [terminated, nodeRayEnd) then being its
    // packet ids; below a flush (rays), the stack size at the flush, under which packets wait.
    bool packetLevel;
    uint flushBase;
    StackEntry next;   // the node a step chose to enter (kStepEnterChild), with its parent's ranges
};

// What every stage of one work item reads.
struct ItemContext {
    WorkItem item;
    uint index;
    uint lane;
    uint rayEnd;
    vec3 rootLo;
    vec3 rootHi;
    vec3 margin;
    uint retireCost;   // the final partition and the probe, reserved in every slice
    // Packets (kPacketFlush): whether this work item's rays travel in them, its packet ids
    // [packetBegin, packetEnd) in the ray id buffer, where a flush gathers its rays, and the
    // ray slot's `terminated` when the work item started.
    bool packets;
    uint packetBegin;
    uint packetEnd;
    uint flushAt;
    uint itemTerminated;
};

// The most rays a packet holds (8x8 pixels), for the leaf balance's and the tight boxes' bound
// on a packet node's rays.
const uint kPacketRays = 64u;

// The rays `packets` packets stand for at most, without overflow.
uint raysOfPackets(uint packets) {
    return min(packets, 0xFFFFFFFFu / kPacketRays) * kPacketRays;
}

const uint kStepContinue = 0u;
const uint kStepOutOfBudget = 1u;
const uint kStepTreeDone = 2u;
const uint kStepEnterChild = 3u;  // Slice::next becomes the node (enterChild)

// A stack entry's rayRule holds, above its rule, the face of the parent's box that the child
// moved (axis * 2, + 1 for the high child's lower face), for its one-face triangle filter;
// kNoFace: the node's own box, whose triangles are the range as it is. Above the face,
// kSiblingWaits marks a near child whose sibling waits on top of the stack for the end of the
// triangles it filters (StackEntry::siblingTriEnd), and kShrunk a node entered again in its
// shrunk box (tightenBox).
const uint kFaceShift = 8u;
const uint kRuleMask = (1u << kFaceShift) - 1u;
const uint kFaceMask = 7u;
const uint kNoFace = 7u;
const uint kSiblingWaits = 1u << 11u;
const uint kShrunk = 1u << 12u;  // the node again, in its shrunk box (tightenBox)
const uint kSiblingNotFiltered = 0xFFFFFFFFu;
const uint kStallsShift = 16u;

// Where the triangles an entry filters end: its sibling's, where the sibling filtered first.
uint filteredTriEnd(StackEntry e) {
    return e.siblingTriEnd != kSiblingNotFiltered ? e.siblingTriEnd : e.triEnd;
}

StackEntry nodeEntry(vec3 lo, vec3 hi, uint rayEnd, uint rule, uint face, uint triBegin, uint triEnd, uint depth,
                     uint stalls) {
    StackEntry e;
    e.lo = lo;
    e.hi = hi;
    e.rayEnd = rayEnd;
    e.triBegin = triBegin;
    e.triEnd = triEnd;
    e.depthAndStalls = depth | (stalls << kStallsShift);
    e.siblingTriEnd = kSiblingNotFiltered;
    e.siblingRayEnd = kSiblingNotFiltered;
    e.pad0 = 0u;
    e.pad1 = 0u;
    e.pad2 = 0u;
    e.rayRule = rule | (face << kFaceShift);
    return e;
}

void loadFrameParameters() {
    gMargin = push.margin;
    gRayOrigin = push.rayOrigin;
    gRayTmin = push.rayTmin;
    gRayTmax = push.rayTmax;
    gAxis = push.axis;
    gOrder = push.order;
    gRayScratchHalf = push.rayScratchHalf;
    gTriScratchHalf = push.triScratchHalf;
    gPacketRaysAt = push.packetRaysAt;
    gDoneFlagsAt = push.doneFlagsAt;
    gPacketIdsAt = push.packetIdsAt;
    gPacketCount = push.packetCount;
    loadArrayBases();
}

// Earlier work items may finish during this very dispatch: one invocation reads the counters
// and the whole workgroup follows its answer, so control flow stays uniform.
bool predecessorsFinished(ItemContext c) {
    if (c.lane == 0)
        sReady = atomicAdd(regions[c.item.rayRegion].rayItemsDone, 0u) == c.item.raySeq &&
                 atomicAdd(regions[c.item.triRegion].triItemsDone, 0u) == c.item.triSeq;
    workgroupSync();
    if (!sReady) {
        if (c.lane == 0) atomicAdd(counters.notReady, 1u);
        return false;
    }
    memoryBarrierBuffer();  // see the finished work items' writes (they barrier before counting)
    return true;
}

// Marks the work item finished and lets its successors on the same ranges run.
void markFinished(ItemContext c) {
    states[c.index].phase = kPhaseFinished;
    atomicAdd(counters.itemsFinished, 1u);
    memoryBarrierBuffer();
    atomicAdd(regions[c.item.rayRegion].rayItemsDone, 1u);
    atomicAdd(regions[c.item.triRegion].triItemsDone, 1u);
}

// A new work item: the rays that may cross the triangles' region go first, at the root.
// Returns false when even that does not fit one slice.
bool startAtRoot(ItemContext c, inout Slice s) {
    if (c.lane == 0) atomicAdd(counters.workItemsRun, 1u);
    s.spent = partitionCost(c.rayEnd - s.terminated);
    s.costBefore = 0u;
    s.stackSlot = 0u;
    if (overBudget(s.spent, c.retireCost)) {
        if (c.lane == 0) atomicAdd(counters.tooLarge, 1u);
        return false;
    }
    s.flushBase = 0;
    if (c.packets) s.terminated = c.packetBegin;
    s.next = nodeEntry(c.rootLo, c.rootHi, c.packets ? c.packetEnd : c.rayEnd, c.packets ? kKeepPacketCrossing : kKeepCrossing,
                       kNoFace, regions[c.item.triRegion].triBegin, regions[c.item.triRegion].triEnd, 0u, 0u);
    s.stackSize = 0;
    s.leafNext = 0;
    s.progressed = true;
    return true;
}

// A work item an earlier slice left off: its node from `states`, its stack from `stacks`.
void resumeSaved(ItemContext c, TraversalState state, inout Slice s) {
    uint start = stageClock();
    s.lo = state.lo;
    s.hi = state.hi;
    s.nodeRayEnd = state.nodeRayEnd;
    s.triBegin = state.triBegin;
    s.triEnd = state.triEnd;
    s.depth = state.depth;
    s.stackSize = state.stackSize;
    s.stalls = state.stalls;
    s.leafNext = state.leafNext;
    s.progressed = false;
    s.costBefore = state.cost;
    s.stackSlot = state.stackSlot;
    s.packetLevel = false;  // a work item with packets never saves (no loop budget)
    s.flushBase = 0u;
    uint from = (s.stackSlot - 1u) * kStackCapacity;  // a saved work item has its slot
    for (uint i = c.lane; i < s.stackSize; i += kWorkgroupSize) sStack[i] = stacks[from + i];
    s.spent = s.stackSize / kWorkgroupSize + 1u;
    workgroupSync();
    addStageTicks(DACRT_STAGE_STACK_AND_SLICES, start);
}

// Tests the leaf's rays from leafNext (or the first live one) against its triangles, as many
// as the budget allows; once all are tested the finished rays are retired from the node.
uint runLeaf(ItemContext c, inout Slice s, uint rayCount, uint triCount) {
    uint from = s.leafNext != 0u ? s.leafNext : s.terminated;
    uint finish = partitionCost(rayCount);
    uint take = s.nodeRayEnd - from;
    if (kLoopBudget != 0u) {
        uint reserved = s.spent + c.retireCost + finish;
        reserved += kStepOverhead;
        take = reserved < kLoopBudget ? leafRaysWithin(take, triCount, kLoopBudget - reserved) : 0u;
        if (take == 0u) return kStepOutOfBudget;
    }
    leafTests(from, from + take, s.triBegin, s.triEnd);
    s.spent += leafTestCost(take, triCount) + kStepOverhead;
    s.progressed = true;
    s.leafNext = from + take;
    if (s.leafNext == s.nodeRayEnd) {
        s.terminated = finishLeaf(s.lo, s.hi, s.terminated, s.nodeRayEnd);
        s.spent += finish;
        s.nodeRayEnd = s.terminated;
        s.leafNext = 0u;
    }
    return kStepContinue;
}

// Front to back: the child on the rays' near side first; the other waits on the stack with
// this node's ranges, which it filters again later. Rays classified per split (kOrderPerRay,
// closest hits) visit the low child if they move up, then all of them the high child, then
// the low child if they move down: two children wait, the high one on top.
StackEntry childEntry(vec3 lo, vec3 hi, Slice s, uint rayRule, int axis, bool highChild) {
    return nodeEntry(lo, hi, s.nodeRayEnd, rayRule, uint(axis) * 2u + (highChild ? 1u : 0u), s.triBegin, s.triEnd,
                     s.depth + 1u, s.stalls);
}

uint splitNode(ItemContext c, inout Slice s, int axis, float split, uint rayCount, uint triCount) {
    uint cost = partitionCost(rayCount) + partitionCost(triCount) + kStepOverhead;
    if (overBudget(s.spent, cost + c.retireCost)) return kStepOutOfBudget;
    s.spent += cost;
    s.progressed = true;
    vec3 lowHi = s.hi, highLo = s.lo;
    lowHi[axis] = split;
    highLo[axis] = split;
    bool perRay = gOrder == kOrderPerRay;  // never with packets (the host's choice)
    bool classified = perRay && !kAnyHit;
    bool lowFirst = perRay || gRayOrigin[axis] <= split;
    vec3 nearLo = lowFirst ? s.lo : highLo, nearHi = lowFirst ? lowHi : s.hi;
    uint crossing = s.packetLevel ? kKeepPacketCrossing : kKeepCrossing;
    if (c.lane == 0) {
        if (classified) {
            sStack[s.stackSize] = childEntry(s.lo, lowHi, s, crossingMovingRule(axis, true), axis, false);
            sStack[s.stackSize + 1u] = childEntry(highLo, s.hi, s, kKeepCrossing, axis, true);
        } else {
            sStack[s.stackSize] = childEntry(lowFirst ? highLo : s.lo, lowFirst ? s.hi : lowHi, s, crossing, axis, lowFirst);
        }
    }
    s.stackSize += classified ? 2u : 1u;
    s.next = childEntry(nearLo, nearHi, s, classified ? crossingMovingRule(axis, false) : crossing, axis, !lowFirst);
    if (!classified) s.next.rayRule |= kSiblingWaits;
    return kStepEnterChild;
}

// A packet node goes on ray by ray: the unfinished rays of its packets are gathered, filtered
// against it and traced from it as rays; the packets below wait on the stack until the rays'
// subtree is done (endFlush).
uint flushPackets(ItemContext c, inout Slice s) {
    uint gathered = gatherPacketRays(s.terminated, s.nodeRayEnd, c.flushAt);
    s.flushBase = s.stackSize;
    s.terminated = c.flushAt;
    s.next = nodeEntry(s.lo, s.hi, gathered, kKeepCrossing, kNoFace, s.triBegin, s.triEnd, s.depth, s.stalls);
    // Its box is as tight as the packet node's: that node tried with at least these rays.
    s.next.rayRule |= kShrunk;
    return kStepEnterChild;
}

// A flush's subtree is done: the rays it finished are flagged, so that no later flush gathers
// them, and the packets take over again.
void endFlush(ItemContext c, inout Slice s) {
    markRaysDone(c.flushAt, s.terminated);
    s.packetLevel = true;
    s.terminated = c.packetBegin;
    s.nodeRayEnd = c.packetBegin;
}

// The far child on top of the stack becomes the node, its rays and triangles filtered again.
uint popFarChild(ItemContext c, inout Slice s) {
    if (c.packets && !s.packetLevel && s.stackSize == s.flushBase) endFlush(c, s);
    if (s.stackSize == 0) return kStepTreeDone;
    uint start = stageClock();
    workgroupSync();
    StackEntry far = sStack[s.stackSize - 1u];
    uint cost = partitionCost(far.rayEnd - s.terminated) + partitionCost(filteredTriEnd(far) - far.triBegin) + kStepOverhead;
    if (overBudget(s.spent, cost + c.retireCost)) return kStepOutOfBudget;
    s.spent += cost;
    s.progressed = true;
    --s.stackSize;
    workgroupSync();  // the slot may be written again before everyone has read it
    addStageTicks(DACRT_STAGE_STACK_AND_SLICES, start);
    s.next = far;
    return kStepEnterChild;
}

// Where the node's rays outnumber its triangles kTightBoxRays times (a packet node: its packets
// counted as full ones), its box shrinks to its cell cut to its triangles' bounds widened by
// the margin (the cpu backend's tight node boxes: docs/correctness.md, "Tight node boxes"), and
// the node is entered again in the shrunk box: its rays (packets) filtered against it widened
// once more, so that neither its leaves nor its children see rays that pass the triangles by,
// its triangles kept as they are. Returns whether it shrank. The node keeps its cell where
// nothing would shrink, or where the box would be empty on an axis (triangles that only reach
// into the cell's margin).
bool tightenBox(ItemContext c, inout Slice s) {
    uint triCount = s.triEnd - s.triBegin, count = s.nodeRayEnd - s.terminated;
    uint rayCount = s.packetLevel ? raysOfPackets(count) : count;
    if (kTightBoxRays == 0u || triCount == 0u || rayCount / max(kTightBoxRays, 1u) < triCount) return false;
    // Under a loop budget the box is an option the slice may not afford (the same hits
    // without it): the reduction and the second partition cost a partition each at most.
    uint cost = partitionCost(triCount) + partitionCost(count) + kStepOverhead;
    if (overBudget(s.spent, cost + c.retireCost)) return false;
    s.spent += cost;
    vec3 boundsLo, boundsHi;
    triangleBoundsBox(s.triBegin, s.triEnd, boundsLo, boundsHi);
    precise vec3 reachLo = boundsLo - c.margin, reachHi = boundsHi + c.margin;
    vec3 lo = max(s.lo, reachLo), hi = min(s.hi, reachHi);
    if (any(greaterThan(lo, hi)) || (all(equal(lo, s.lo)) && all(equal(hi, s.hi)))) return false;
    if (c.lane == 0) atomicAdd(counters.tightBoxes, 1u);
    s.next = nodeEntry(lo, hi, s.nodeRayEnd, s.packetLevel ? kKeepPacketCrossing : kKeepCrossing, kNoFace, s.triBegin,
                       s.triEnd, s.depth, s.stalls);
    s.next.rayRule |= kShrunk;
    return true;
}

// The node the step chose (a split's near child, the far child popped, the root, a flush's
// rays) becomes the current one: its rays (or packets) and triangles filtered from its
// parent's. The traversal's one call of the filters, so that the kernel inlines each once
// (llvmpipe's compile time grows with every copy). A rule known only at run time makes every
// branch of keepRay run under a mask on llvmpipe: the common rules get calls of their own,
// where they are constants. Returns whether the node shrank, to be entered again (tightenBox).
bool enterChild(ItemContext c, inout Slice s) {
    StackEntry e = s.next;
    uint rule = e.rayRule & kRuleMask, face = (e.rayRule >> kFaceShift) & kFaceMask;
    vec3 lo = e.lo - c.margin, hi = e.hi + c.margin;
    s.lo = e.lo;
    s.hi = e.hi;
    s.packetLevel = rule == kKeepPacketCrossing;
    // A second child takes the rays (packets) its sibling dropped untested: they crossed the
    // parent's widened box but not the sibling's, and the two children's widened boxes cover
    // the parent's (docs/correctness.md, "The second child's rays"; a ray given to a cell it
    // does not cross changes no hit). Its sibling's subtree traced only the rays it kept.
    // (Clamped to the range, so that a broken invariant would cost tests, never ray ids.)
    uint certainFrom = e.siblingRayEnd != kSiblingNotFiltered ? clamp(e.siblingRayEnd, s.terminated, e.rayEnd) : e.rayEnd;
    s.nodeRayEnd = rule == kKeepCrossing        ? partitionRaysFrom(s.terminated, e.rayEnd, certainFrom, kKeepCrossing, lo, hi)
                   : rule == kKeepPacketCrossing ? partitionPackets(s.terminated, e.rayEnd, certainFrom, lo, hi)
                                                 : partitionRays(s.terminated, e.rayEnd, rule, lo, hi);
    bool ownBox = face == kNoFace;
    bool hasRays = s.nodeRayEnd > s.terminated;
    int faceAxis = int(face >> 1u);
    bool highChild = (face & 1u) != 0u;
    // A second child whose sibling filtered the parent's triangles takes those of the sibling's
    // that reach past the split (moved to the end of the sibling's range) and every one behind
    // it, which the sibling did not take: they lie beyond its face, inside this child's cell.
    bool afterSibling = !ownBox && hasRays && e.siblingTriEnd != kSiblingNotFiltered;
    uint filtered = !ownBox && hasRays ? partitionTrianglesAtFace(e.triBegin, filteredTriEnd(e), lo, hi, faceAxis, highChild, afterSibling)
                                       : e.triBegin;
    s.triBegin = afterSibling ? filtered : e.triBegin;
    s.triEnd = ownBox ? e.triEnd : (afterSibling ? e.triEnd : filtered);
    if ((e.rayRule & kSiblingWaits) != 0u && c.lane == 0) {
        sStack[s.stackSize - 1u].siblingTriEnd = hasRays ? s.triEnd : kSiblingNotFiltered;
        sStack[s.stackSize - 1u].siblingRayEnd = s.nodeRayEnd;
    }
    s.depth = e.depthAndStalls & ((1u << kStallsShift) - 1u);
    uint stalls = e.depthAndStalls >> kStallsShift;
    s.stalls = ownBox ? stalls
                      : (s.nodeRayEnd == e.rayEnd && s.triBegin == e.triBegin && s.triEnd == e.triEnd ? stalls + 1u : 0u);
    return hasRays && (e.rayRule & kShrunk) == 0u && tightenBox(c, s);
}

// A leaf tests every one of its rays against every one of its triangles, a split only
// partitions them. A node of a few rays over thousands of triangles (a band's rays thinning out
// high in the tree, or a cluster of triangles in a corner of a big box that three splits in a row
// have not separated) made a leaf cost up to 60 times a split: on the Dragon at 1920x1080 under
// the discrete profile such leaves were the costliest work items of Step 1 (docs/gpu.md, "The
// gpu profiles"). With kLeafOverSplit, a node whose leaf would cost more than that many splits
// splits on while its box can (the maximum depth still bounds it): another tree, the same hits.
bool leafCostsMoreThanSplits(uint rayCount, uint triCount) {
    return kLeafOverSplit != 0u &&
           leafTestCost(rayCount, triCount) > kLeafOverSplit * (partitionCost(rayCount) + partitionCost(triCount) + kStepOverhead);
}

// A packet node splits as a ray node does, or goes on ray by ray where it has fewer than
// kPacketFlush packets, or where its rays would be a leaf at once, however many they are.
uint stepPacketNode(ItemContext c, inout Slice s, int axis, float split) {
    uint packetCount = s.nodeRayEnd - s.terminated, triCount = s.triEnd - s.triBegin;
    bool canSplit = s.depth < kMaxDepth && split > s.lo[axis] && split < s.hi[axis] &&
                    s.stalls < DACRT_MAX_STALLED_SPLITS;
    bool flush = packetCount < kPacketFlush || triCount < kTriLimit || !canSplit ||
                 leafUnderBalance(raysOfPackets(packetCount), triCount, kLeafBalance);
    return flush ? flushPackets(c, s) : splitNode(c, s, axis, split, packetCount, triCount);
}

// One step of the depth-first traversal: a leaf (or a slice of one), a split, or a pop.
uint stepTraversal(ItemContext c, inout Slice s) {
    if (!(s.terminated < s.nodeRayEnd && s.triBegin < s.triEnd)) return popFarChild(c, s);
    uint rayCount = s.nodeRayEnd - s.terminated, triCount = s.triEnd - s.triBegin;
    int axis = longestAxis(s.lo, s.hi);
    float split = 0.5 * (s.lo[axis] + s.hi[axis]);
    if (s.packetLevel) return stepPacketNode(c, s, axis, split);
    bool costly = leafCostsMoreThanSplits(rayCount, triCount);
    bool canSplit = s.depth < kMaxDepth && split > s.lo[axis] && split < s.hi[axis] &&
                    (s.stalls < DACRT_MAX_STALLED_SPLITS || costly);
    bool isLeaf = (rayCount < kRayLimit && !costly) || triCount < kTriLimit || !canSplit || s.leafNext != 0u ||
                  leafUnderBalance(rayCount, triCount, kLeafBalance);
    // Under a loop budget a leaf too large for half a slice splits further instead while
    // splitting still separates something: another tree, the same hits (every tree gives
    // brute force's answer). A leaf that must stay one runs in slices.
    if (isLeaf && canSplit && s.leafNext == 0u && kLoopBudget != 0u && leafCost(rayCount, triCount) > kLoopBudget / 2u)
        isLeaf = false;
    return isLeaf ? runLeaf(c, s, rayCount, triCount) : splitNode(c, s, axis, split, rayCount, triCount);
}

// Out of budget: the node and the stack are saved, and a later dispatch resumes here. A work
// item's first save takes the next free stack slot: few work items ever save, so the buffer
// holds fewer stacks than there are work items; past its last slot nothing is written, and
// the host fails the frame (stackSlotsTaken).
void saveSlice(ItemContext c, Slice s) {
    uint start = stageClock();
    if (!s.progressed && c.lane == 0) atomicAdd(counters.tooLarge, 1u);
    if (s.stackSlot == 0u) {
        if (c.lane == 0) sStackSlot = atomicAdd(counters.stackSlotsTaken, 1u) + 1u;
        workgroupSync();
        s.stackSlot = sStackSlot;
    }
    workgroupSync();
    if (s.stackSlot <= push.stackSlots)
        for (uint i = c.lane; i < s.stackSize; i += kWorkgroupSize) stacks[(s.stackSlot - 1u) * kStackCapacity + i] = sStack[i];
    bool cutShort = loopLimiterFired(push.loopProbe);
    if (c.lane == 0) {
        TraversalState saved;
        saved.lo = s.lo;
        saved.hi = s.hi;
        saved.phase = kPhaseRunning;
        saved.nodeRayEnd = s.nodeRayEnd;
        saved.triBegin = s.triBegin;
        saved.triEnd = s.triEnd;
        saved.depth = s.depth;
        saved.stackSize = s.stackSize;
        saved.stalls = s.stalls;
        saved.leafNext = s.leafNext;
        saved.cost = s.costBefore + s.spent;
        saved.stackSlot = s.stackSlot;
        states[c.index] = saved;
        regions[c.item.rayRegion].terminated = s.terminated;
        if (cutShort) atomicAdd(counters.loopLimitHits, 1u);
    }
    addStageTicks(DACRT_STAGE_STACK_AND_SLICES, start);
}

// The tree is done: rays no later work item can change are finished here (see RetireRule on
// the CPU side), and the work item is marked finished.
void retireRays(ItemContext c, Slice s) {
    // With packets the slot's ray ids are as the work item found them: the rays its flushes
    // finished go first, as the traversal of rays would have left them.
    if (c.packets) s.terminated = partitionRays(c.itemTerminated, c.rayEnd, kKeepDone, c.rootLo, c.rootHi);
    uint rule = c.item.retire == 0u ? kKeepStill : (c.item.retire == 1u ? kKeepStuckHigh : kKeepStuckLow);
    uint before = s.terminated;
    uint terminated = partitionRays(s.terminated, c.rayEnd, rule, c.rootLo - c.margin, c.rootHi + c.margin);
    if (c.packets) markRaysDone(before, terminated);  // no later flush gathers them
    bool cutShort = loopLimiterFired(push.loopProbe);
    if (c.lane == 0) {
        atomicAdd(counters.raysRetired, terminated - before);
        if (c.item.retire == 0u) atomicAdd(counters.terminatedStep1, terminated - regions[c.item.rayRegion].rayBegin);
        regions[c.item.rayRegion].terminated = terminated;
        if (cutShort) atomicAdd(counters.loopLimitHits, 1u);
        // The work item's cost, read back for the work item report (the final partition and
        // the probe as the slice reserved them).
        states[c.index].cost = s.costBefore + s.spent + c.retireCost;
        markFinished(c);
    }
}

// One launch of the workgroup's work item: nothing if it is finished or must wait, else a
// slice of its traversal.
void runWorkItem(inout ItemContext c) {
    TraversalState state = states[c.index];
    if (state.phase == kPhaseFinished) return;
    uint waitStart = stageClock();
    if (!predecessorsFinished(c)) {
        addStageTicks(DACRT_STAGE_WAITING, waitStart);
        return;
    }
    if (c.lane == 0) atomicAdd(counters.slices, 1u);
    Slice s;
    s.terminated = regions[c.item.rayRegion].terminated;
    c.rayEnd = regions[c.item.rayRegion].rayEnd;
    c.rootLo = regions[c.item.triRegion].lo;
    c.rootHi = regions[c.item.triRegion].hi;
    c.margin = vec3(gMargin);
    c.retireCost = partitionCost(c.rayEnd - s.terminated) + 4u;
    c.packets = kPacketFlush != 0u && c.item.packetBegin < c.item.packetEnd;
    c.packetBegin = gPacketIdsAt + c.item.packetBegin;
    c.packetEnd = gPacketIdsAt + c.item.packetEnd;
    c.flushAt = gRayScratchHalf / 2u + regions[c.item.rayRegion].rayBegin;  // packets: the scratch half is at 2n
    c.itemTerminated = s.terminated;

    // Nothing to trace (no live ray, or, in a transfer, none moving towards the triangles'
    // region): finish at once.
    uint towards = c.item.retire == 1u ? kTowardHigh : (c.item.retire == 2u ? kTowardLow : kTowardLow | kTowardHigh);
    bool noneMoving = c.item.retire != 0u && (regions[c.item.rayRegion].directions & towards) == 0u;
    if (state.phase == kPhaseNew && (s.terminated >= c.rayEnd || noneMoving)) {
        if (c.lane == 0) {
            atomicAdd(counters.workItemsEmpty, 1u);
            markFinished(c);
        }
        return;
    }
    uint outcome = kStepContinue;
    if (state.phase == kPhaseNew) {
        if (!startAtRoot(c, s)) return;
        outcome = kStepEnterChild;
    } else {
        resumeSaved(c, state, s);
    }

    while (outcome == kStepContinue || outcome == kStepEnterChild) {
        if (outcome == kStepEnterChild && enterChild(c, s)) continue;  // s.next: the node in its shrunk box
        outcome = stepTraversal(c, s);
    }
    if (outcome == kStepOutOfBudget)
        saveSlice(c, s);
    else
        retireRays(c, s);
}

void main() {
    uint launchStart = stageClock();
    clearStageTicks();
    loadFrameParameters();
    ItemContext c;
    c.lane = gl_LocalInvocationIndex;
    c.index = push.firstWorkItem + gl_WorkGroupID.x;
    c.item = workItems[c.index];
    runWorkItem(c);
    endLaunchTicks(launchStart);
    publishStageTicks(c.lane);
}
