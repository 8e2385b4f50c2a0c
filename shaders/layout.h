// Data layouts shared by the C++ host and the GLSL compute shaders (std430).
// Included verbatim by both: C++ sees glm types through host/core/shader_layout.hpp,
// GLSL sees its own. Every size and offset is checked at the end of this file.
#ifndef DACRT_LAYOUT_H
#define DACRT_LAYOUT_H

// A ray. Primary rays are made on the host (makeRay); secondary rays on the host or the
// device by shaders/secondary_rays.glsl, whose division and square root are correctly rounded
// in integer arithmetic: every backend starts from bit-identical inputs.
struct Ray {
    vec3 origin;
    float tmin;     // hits must have t > tmin
    vec3 dir;       // of any length: t is in units of it
    uint axes;      // watertight test permutation: kx | ky << 2 | kz << 4
    vec3 invDir;    // 1/dir per component, 0 where dir is 0 (the box test branches on dir == 0)
    float tmax;     // hits must have t <= tmax: kNoHitT for a whole ray, the segment's end otherwise
    vec3 shear;     // watertight test: (dir[kx]/dir[kz], dir[ky]/dir[kz], 1/dir[kz])
    float pad1;
};

struct Triangle {
    vec3 v0;
    uint cullBackFace;  // 1: a ray that meets the back face does not hit it (backFaceIsCulled)
    vec3 v1;
    float pad1;
    vec3 v2;
    float pad2;
};

// Axis-aligned bounds; also the per-triangle bounds used by the triangle/cell filter.
struct Bounds {
    vec3 lo;
    float pad0;
    vec3 hi;
    float pad1;
};

const uint kMissPrim = 0xFFFFFFFFu;
const float kNoHitT = 3.402823466e+38;          // FLT_MAX: finite, so no inf arithmetic anywhere

// Per-ray result. prim == kMissPrim means no hit; t is then the ray's tmax (kNoHitT for a
// whole ray): every backend starts each ray's best hit there (missHit), so a segment's end
// bounds its filters like a hit. Secondary passes mark the slots of rays they did not make
// (a surface facing away from the light, say) with kNotTracedPrim.
const uint kNotTracedPrim = 0xFFFFFFFEu;
// An any-hit answer that does not name its triangle (Embree's occlusion query): a hit, prim unknown.
const uint kUnnamedHitPrim = 0xFFFFFFFDu;
struct Hit {
    float t;
    uint prim;
    float u;   // barycentric weight of v1
    float v;   // barycentric weight of v2
};

// One sub-scene of the parallel scheme: a slab of the scene box along the division axis.
struct Region {
    vec3 lo;
    uint rayBegin;
    vec3 hi;
    uint rayEnd;
    uint triBegin;
    uint triEnd;
    uint terminated;     // rays [rayBegin, terminated) have their final hit
    uint rayItemsDone;   // gpu: finished work items that traced this region's rays
    uint triItemsDone;   // gpu: finished work items that used this region's triangles
    uint directions;     // gpu: kTowardLow | kTowardHigh where some ray of the region moves that way
    uint cursor;         // gpu: the next free ray id slot while secondary rays are binned
    uint pad2;
};
const uint kTowardLow = 1u;
const uint kTowardHigh = 2u;

// One work item of a dispatch: the live rays of one region against the triangles of another
// (the same region in Step 1). retire: 0 = rays that do not move along the division axis,
// 1 / 2 = rays moving toward higher / lower regions that cannot reach triRegion.
// raySeq / triSeq: how many earlier work items use the same rays / triangles. A work item
// runs only when exactly that many have finished, so work items that share ranges never run
// at once and always run in schedule order, however many dispatches they take.
struct WorkItem {
    uint rayRegion;
    uint triRegion;
    uint retire;
    uint raySeq;
    uint triSeq;
    uint packetBegin;  // its ray slot's packets [packetBegin, packetEnd) (DACRT_SPEC_PACKET_FLUSH), else empty
    uint packetEnd;
    uint pad2;
};

// A ray packet of the kernel (DACRT_SPEC_PACKET_FLUSH): the rays of one 8x8 pixel tile of one
// ray slot, at [rayBegin, rayEnd) of the ray id buffer's packet rays (DacrtPush::packetRaysAt),
// with the smallest and largest invDir of its rays per axis. Rays that share their start
// compute (lo - origin) * invDir with the same first factor and rounding is monotone, so the
// four corner products bound every ray's rounded slab values (the cpu backend's RayPacket). An
// axis where some ray's invDir is 0 (the filter's branch) or not finite is left unbounded.
struct PacketBounds {
    vec3 invLo;
    uint rayBegin;
    vec3 invHi;
    uint rayEnd;
    uint unboundedAxes;  // bit per axis
    uint pad0;
    uint pad1;
    uint pad2;
};

// A work item's traversal between dispatches: llvmpipe ends a shader invocation after 65535
// loop iterations, so a large work item runs in slices, each resuming where the last stopped.
struct TraversalState {
    vec3 lo;           // the current node (empty when nodeRayEnd <= terminated)
    uint phase;        // 0 not started, 1 running, 2 finished
    vec3 hi;
    uint nodeRayEnd;
    uint triBegin;
    uint triEnd;
    uint depth;
    uint stackSize;
    uint stalls;       // splits in a row that kept every ray and triangle (DACRT_MAX_STALLED_SPLITS)
    uint leafNext;     // a leaf in progress: its rays before this were tested; 0 when none
    uint cost;         // loop iterations of the kernel's cost model spent so far, over every slice
    uint stackSlot;    // where its stack waits between slices: slot stackSlot - 1 of `stacks`; 0: none yet
};

struct StackEntry {   // a child waiting, with its parent's ranges
    vec3 lo;
    uint rayEnd;
    vec3 hi;
    uint triBegin;
    uint triEnd;
    uint depthAndStalls;  // the child's depth, and above bit 16 the parent's stalled splits
    // Where its sibling's triangles end when the sibling went first and filtered the parent's
    // [triBegin, triEnd): the child then filters [triBegin, siblingTriEnd) only, the rest of
    // the range being its own already; kSiblingNotFiltered otherwise.
    uint siblingTriEnd;
    uint rayRule;     // which of the parent's live rays visit it (kKeepCrossing*), its face, kSiblingWaits
    // Likewise for its rays (or packets): where the sibling's filter put those it kept. The
    // parent's rays behind them, which the sibling dropped, visit this child untested.
    uint siblingRayEnd;
    uint pad0;
    uint pad1;
    uint pad2;
};

// Which child of a split each ray meets first (FrameGeometry::order).
const uint kOrderNearSide = 0u;   // the child on rayOrigin's side, for every ray
const uint kOrderPerRay = 1u;     // per split, by the sign of each ray's direction

// Push constants of the DACRT kernel.
struct DacrtPush {
    vec3 rayOrigin;        // FrameGeometry::nearSide (kOrderNearSide): the shared origin when there is one
    float margin;          // filter widening (filterMargin)
    uint firstWorkItem;    // this dispatch's work items are [firstWorkItem, + group count)
    uint axis;             // division axis
    uint rayScratchHalf;   // ray id count: the ray id buffer's second half, scratch, starts here
    uint triScratchHalf;   // triangle id count: likewise in the triangle id buffer
    uint loopProbe;        // 2; a loop of this many iterations at the end detects a loop limiter
    float rayTmin;         // every ray's tmin, where DACRT_SPEC_SHARED_START or _SHARED_SEGMENT says they share it
    uint order;            // kOrder*
    uint stackSlots;       // traversal stacks the stack buffer holds (taken in turn by work items that save one)
    // With packets (DACRT_SPEC_PACKET_FLUSH), the ray id buffer holds after the ray ids (n):
    // the rays gathered from packets [n, 2n), the scratch half [2n, 4n) (rayScratchHalf 2n),
    // then these sections; all 0 without packets.
    uint packetRaysAt;     // each slot's ray ids by tile, at the slot's own positions
    uint doneFlagsAt;      // one flag per ray id: nonzero once the ray has its final hit
    uint packetIdsAt;      // packet ids, then as many again of scratch
    uint packetCount;      // packet ids (the scratch is that far behind them)
    float rayTmax;         // every ray's tmax, where DACRT_SPEC_SHARED_SEGMENT says they share it
};

// A light as a secondary pass traces it (from Scene::lights or --light), in float32.
const uint kLightPoint = 0u;
const uint kLightSpot = 1u;
const uint kLightDirectional = 2u;
struct ShadowLight {
    vec3 position;         // point, spot
    uint type;             // kLight*
    vec3 direction;        // spot, directional: where the light travels, unit
    float range;           // 0: unlimited
    float cosOuterSquared; // spot: cos^2 of the outer cone angle (at most pi/2)
    float pad0;
    float pad1;
    float pad2;
};

// What a secondary pass makes from each primary hit.
const uint kPassShadow = 0u;      // one ray towards the light
const uint kPassOcclusion = 1u;   // raysPerHit cosine-distributed rays of length occlusionDistance

// Push constants of shaders/secondary.comp: ray generation and binning of one secondary pass.
struct SecondaryPush {
    ShadowLight light;
    uint kind;             // kPass*
    uint step;             // 0: make rays and count them per region, 1: region ranges, 2: ray ids
    uint sourceCount;      // primary rays (pixels)
    uint raysPerHit;       // rays per primary hit: slot s * raysPerHit + k
    float occlusionDistance;
    uint sampleSeed;       // kPassOcclusion: the sample sequence (a frame's)
    uint regionCount;      // slabs along axis
    uint groups;           // ray groups: region k's group g is slot k * groups + g
    uint axis;
    float margin;          // filterMargin of the frame
    uint firstInvocation;  // this dispatch's invocations are [firstInvocation, + its size)
    uint firstSample;      // kPassOcclusion: the pass holds samples [firstSample, + raysPerHit) ...
    uint samplesPerHit;    // ... of this many per hit: sample k of source s is stream s * samplesPerHit + k
    uint pad1;
    uint pad2;
    uint pad3;
};

// The stages a work item's clock ticks are told apart by (shaders/stage_clocks.glsl): every
// ray filter (the leaves' and the final retire included), every triangle filter, the leaves'
// tests, the stack and the slices (a pop's wait, saving and resuming), a launch that finds a
// predecessor still running, and every launch from start to end, which holds all the others.
#define DACRT_STAGE_RAY_PARTITIONS 0
#define DACRT_STAGE_TRIANGLE_PARTITIONS 1
#define DACRT_STAGE_LEAF_TESTS 2
#define DACRT_STAGE_STACK_AND_SLICES 3
#define DACRT_STAGE_WAITING 4
#define DACRT_STAGE_LAUNCHES 5
#define DACRT_STAGE_COUNT 6

// Counters the kernel adds to with atomics (32-bit: a frame stays far below 2^32 tests).
struct GpuCounters {
    uint workItemsRun;
    uint workItemsEmpty;
    uint rayBoxTests;
    uint rayTriangleTests;
    uint leaves;
    uint raysRetired;
    uint testResult;   // workgroup_test.comp's answer
    uint loopLimitHits;  // work items cut short by a driver's loop limiter (llvmpipe: 65535)
    uint itemsFinished;
    uint slices;         // work item slices run (a work item that fits runs in one)
    uint notReady;       // work item launches that found an earlier one still running
    uint tooLarge;       // work items with a single step beyond the loop budget
    uint terminatedStep1;  // rays finished by Step 1 work items (hit or retired), as the cpu backend counts them
    uint stackSlotsTaken;  // work items that saved a stack (more than DacrtPush::stackSlots: the frame fails)
    uint raysCulled;       // secondary.comp: rays made that miss the division's widened box (no region)
    uint packetBoxTests;   // packets tested against a cell (each stands for its rays)
    uint tightBoxes;       // nodes whose box shrank to their triangles' bounds (kTightBoxRays)
    // The kernel's stage clocks (the DACRT_STAGE_CLOCKS build, --stage-clocks): clock ticks
    // each stage took over the frame's work items, as 64-bit sums of (low, high) words.
    uint stageTicks[2 * DACRT_STAGE_COUNT];
};

// Push constants of workgroup_test.comp, which runs one building block of the DACRT kernel
// in a single workgroup so that tests can compare it with the CPU.
struct WorkgroupTestPush {
    vec3 lo;
    uint mode;             // 0: partitionRays, 1: partitionTriangles, 2: leaf
    vec3 hi;
    uint rule;             // partitionRays: kKeep* rule
    uint begin;            // ray range (modes 0 and 2) or triangle range (mode 1)
    uint end;
    uint triBegin;         // leaf triangles
    uint triEnd;
    uint rayScratchHalf;
    uint triScratchHalf;
    uint axis;
    uint loopProbe;        // 2, as DacrtPush::loopProbe
};

// Storage buffer bindings of the DACRT kernel (set 0).
#define DACRT_BINDING_RAYS 0
#define DACRT_BINDING_TRIANGLES 1
#define DACRT_BINDING_TRIANGLE_BOUNDS 2
#define DACRT_BINDING_HITS 3
#define DACRT_BINDING_RAY_IDS 4      // the ray ids, then as many again of scratch
#define DACRT_BINDING_TRI_IDS 5      // the triangle ids, then as many again of scratch
#define DACRT_BINDING_REGIONS 6
#define DACRT_BINDING_WORK_ITEMS 7
#define DACRT_BINDING_COUNTERS 8
#define DACRT_BINDING_STATES 9
#define DACRT_BINDING_STACKS 10
#define DACRT_BINDING_SOURCE_RAYS 11   // secondary passes: the primary rays, read by shaders/secondary.comp
#define DACRT_BINDING_SOURCE_HITS 12   // secondary passes: the primary hits
// The addressed kernels (DACRT_ADDRESSED): where an array is larger than one binding may be
// (maxStorageBufferRange), the arrays below are reached by device address instead, each in
// chunks of at most DACRT_SPEC_CHUNK_BYTES (an allocation's limit). This buffer holds, per
// array, the index of its first chunk (uint firstChunk[DACRT_ADDRESSED_ARRAYS]), then every
// chunk's address (uvec2: low, high word) from byte DACRT_CHUNK_TABLE_ADDRESSES.
#define DACRT_BINDING_ADDRESSES 13
#define DACRT_BINDING_PACKETS 14       // PacketBounds of the frame's packets (DACRT_SPEC_PACKET_FLUSH)
#define DACRT_BINDING_COUNT 15

// The addressed arrays, by their index in the chunk table.
#define DACRT_ARRAY_RAYS 0u
#define DACRT_ARRAY_TRIANGLES 1u
#define DACRT_ARRAY_TRIANGLE_BOUNDS 2u
#define DACRT_ARRAY_HITS 3u
#define DACRT_ARRAY_RAY_IDS 4u
#define DACRT_ARRAY_TRI_IDS 5u
#define DACRT_ARRAY_SOURCE_RAYS 6u
#define DACRT_ARRAY_SOURCE_HITS 7u
#define DACRT_ADDRESSED_ARRAYS 8
#define DACRT_CHUNK_TABLE_ADDRESSES 32
// A chunk's size is a multiple of every addressed element's (64, 48, 32, 16 and 4 bytes), so
// that no element straddles two chunks.
#define DACRT_CHUNK_ALIGNMENT 192u

// A split whose child keeps every ray and every triangle of its parent made no progress;
// after this many such splits in a row the node is a leaf. Identical rays meeting coincident
// triangles never separate, and without this rule the traversal visits every cell along
// their path down to the maximum depth (docs/stability.md).
#define DACRT_MAX_STALLED_SPLITS 3u

// Specialization constants of the DACRT kernel (constant_id).
#define DACRT_SPEC_WORKGROUP_SIZE 0
#define DACRT_SPEC_RAY_LIMIT 1
#define DACRT_SPEC_TRI_LIMIT 2
#define DACRT_SPEC_MAX_DEPTH 3
#define DACRT_SPEC_LOOP_BUDGET 4
#define DACRT_SPEC_SHARED_START 5   // 1: every ray has origin rayOrigin and tmin rayTmin (DacrtPush)
#define DACRT_SPEC_ANY_HIT 6        // 1: a ray ends at its first hit in its segment (shadow, occlusion)
#define DACRT_SPEC_CHUNK_BYTES 7    // the addressed kernels: bytes of every chunk but an array's last
#define DACRT_SPEC_LEAF_OVER_SPLIT 8  // 0, or how many splits' cost a leaf may reach (kLeafOverSplit)
#define DACRT_SPEC_LOCKSTEP_SUBGROUPS 9  // 1: the workgroup is one subgroup, run as one SIMD thread (llvmpipe)
#define DACRT_SPEC_LEAF_BALANCE 10     // 0, or the leaf balance (kLeafBalance, shaders/leaf_rule.glsl)
#define DACRT_SPEC_PACKET_FLUSH 11     // 0, or packets: a node with fewer goes on ray by ray (kPacketFlush)
#define DACRT_SPEC_SHARED_SEGMENT 12   // 1: any-hit rays that all have tmin rayTmin and tmax rayTmax (DacrtPush)
#define DACRT_SPEC_TIGHT_BOX_RAYS 13    // 0, or rays per triangle from which a node shrinks its box (kTightBoxRays)
#define DACRT_SPEC_COUNT 14

#ifdef __cplusplus
static_assert(sizeof(WorkItem) == 32);
static_assert(offsetof(WorkItem, triRegion) == 4 && offsetof(WorkItem, retire) == 8);
static_assert(offsetof(WorkItem, raySeq) == 12 && offsetof(WorkItem, triSeq) == 16);
static_assert(sizeof(TraversalState) == 64 && offsetof(TraversalState, phase) == 12);
static_assert(offsetof(TraversalState, stalls) == 48 && offsetof(TraversalState, leafNext) == 52);
static_assert(offsetof(TraversalState, cost) == 56 && offsetof(TraversalState, stackSlot) == 60);
static_assert(offsetof(TraversalState, nodeRayEnd) == 28 && offsetof(TraversalState, stackSize) == 44);
static_assert(sizeof(StackEntry) == 64 && offsetof(StackEntry, rayEnd) == 12 && offsetof(StackEntry, depthAndStalls) == 36);
static_assert(offsetof(StackEntry, siblingTriEnd) == 40 && offsetof(StackEntry, rayRule) == 44);
static_assert(offsetof(StackEntry, siblingRayEnd) == 48);
static_assert(sizeof(DacrtPush) == 68 && offsetof(DacrtPush, loopProbe) == 32 && offsetof(DacrtPush, rayTmax) == 64);
static_assert(offsetof(DacrtPush, packetRaysAt) == 48 && offsetof(DacrtPush, doneFlagsAt) == 52);
static_assert(offsetof(DacrtPush, packetIdsAt) == 56 && offsetof(DacrtPush, packetCount) == 60);
static_assert(offsetof(WorkItem, packetBegin) == 20 && offsetof(WorkItem, packetEnd) == 24);
static_assert(sizeof(PacketBounds) == 48 && offsetof(PacketBounds, rayBegin) == 12);
static_assert(offsetof(PacketBounds, invHi) == 16 && offsetof(PacketBounds, rayEnd) == 28);
static_assert(offsetof(PacketBounds, unboundedAxes) == 32);
static_assert(offsetof(DacrtPush, rayTmin) == 36 && offsetof(DacrtPush, order) == 40);
static_assert(offsetof(DacrtPush, stackSlots) == 44);
static_assert(sizeof(ShadowLight) == 48 && offsetof(ShadowLight, type) == 12);
static_assert(offsetof(ShadowLight, direction) == 16 && offsetof(ShadowLight, range) == 28);
static_assert(offsetof(ShadowLight, cosOuterSquared) == 32);
static_assert(sizeof(SecondaryPush) == 112 && offsetof(SecondaryPush, kind) == 48);
static_assert(offsetof(SecondaryPush, firstSample) == 92 && offsetof(SecondaryPush, samplesPerHit) == 96);
static_assert(offsetof(SecondaryPush, sourceCount) == 56 && offsetof(SecondaryPush, occlusionDistance) == 64);
static_assert(offsetof(SecondaryPush, sampleSeed) == 68 && offsetof(SecondaryPush, groups) == 76);
static_assert(offsetof(SecondaryPush, axis) == 80 && offsetof(SecondaryPush, margin) == 84);
static_assert(offsetof(SecondaryPush, firstInvocation) == 88);
static_assert(offsetof(DacrtPush, rayOrigin) == 0 && offsetof(DacrtPush, margin) == 12);
static_assert(offsetof(DacrtPush, firstWorkItem) == 16 && offsetof(DacrtPush, axis) == 20);
static_assert(offsetof(DacrtPush, rayScratchHalf) == 24 && offsetof(DacrtPush, triScratchHalf) == 28);
static_assert(offsetof(GpuCounters, raysRetired) == 20);
static_assert(offsetof(GpuCounters, terminatedStep1) == 48 && offsetof(GpuCounters, stackSlotsTaken) == 52);
static_assert(offsetof(GpuCounters, raysCulled) == 56 && offsetof(GpuCounters, packetBoxTests) == 60);
static_assert(offsetof(GpuCounters, tightBoxes) == 64);
static_assert(offsetof(GpuCounters, stageTicks) == 68 && sizeof(GpuCounters) == 68 + 8 * DACRT_STAGE_COUNT);
static_assert(offsetof(GpuCounters, itemsFinished) == 32 && offsetof(GpuCounters, tooLarge) == 44);
static_assert(offsetof(GpuCounters, testResult) == 24 && offsetof(GpuCounters, loopLimitHits) == 28);
static_assert(sizeof(WorkgroupTestPush) == 64 && offsetof(WorkgroupTestPush, mode) == 12);
static_assert(offsetof(WorkgroupTestPush, rule) == 28 && offsetof(WorkgroupTestPush, begin) == 32);
static_assert(offsetof(WorkgroupTestPush, triEnd) == 44 && offsetof(WorkgroupTestPush, axis) == 56);
static_assert(offsetof(WorkgroupTestPush, loopProbe) == 60);
static_assert(DACRT_CHUNK_ALIGNMENT % sizeof(Ray) == 0 && DACRT_CHUNK_ALIGNMENT % sizeof(Triangle) == 0);
static_assert(DACRT_CHUNK_ALIGNMENT % sizeof(Bounds) == 0 && DACRT_CHUNK_ALIGNMENT % sizeof(Hit) == 0);
static_assert(DACRT_CHUNK_TABLE_ADDRESSES == DACRT_ADDRESSED_ARRAYS * sizeof(uint));
static_assert(sizeof(Ray) == 64);
static_assert(offsetof(Ray, origin) == 0 && offsetof(Ray, tmin) == 12);
static_assert(offsetof(Ray, dir) == 16 && offsetof(Ray, axes) == 28);
static_assert(offsetof(Ray, invDir) == 32 && offsetof(Ray, tmax) == 44 && offsetof(Ray, shear) == 48);
static_assert(sizeof(Triangle) == 48);
static_assert(offsetof(Triangle, cullBackFace) == 12);
static_assert(offsetof(Triangle, v0) == 0 && offsetof(Triangle, v1) == 16 && offsetof(Triangle, v2) == 32);
static_assert(sizeof(Bounds) == 32 && offsetof(Bounds, lo) == 0 && offsetof(Bounds, hi) == 16);
static_assert(sizeof(Hit) == 16 && offsetof(Hit, t) == 0 && offsetof(Hit, prim) == 4);
static_assert(offsetof(Hit, u) == 8 && offsetof(Hit, v) == 12);
static_assert(sizeof(Region) == 64);
static_assert(offsetof(Region, rayItemsDone) == 44 && offsetof(Region, triItemsDone) == 48);
static_assert(offsetof(Region, lo) == 0 && offsetof(Region, rayBegin) == 12);
static_assert(offsetof(Region, hi) == 16 && offsetof(Region, rayEnd) == 28);
static_assert(offsetof(Region, triBegin) == 32 && offsetof(Region, triEnd) == 36);
static_assert(offsetof(Region, terminated) == 40);
static_assert(offsetof(Region, directions) == 52 && offsetof(Region, cursor) == 56);
#endif

#endif
