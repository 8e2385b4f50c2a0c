// Buffers, specialization constants and shared memory of the DACRT kernels.
#ifndef DACRT_BINDINGS_GLSL
#define DACRT_BINDINGS_GLSL

layout(local_size_x_id = DACRT_SPEC_WORKGROUP_SIZE) in;
layout(constant_id = DACRT_SPEC_RAY_LIMIT) const uint kRayLimit = 16;
layout(constant_id = DACRT_SPEC_TRI_LIMIT) const uint kTriLimit = 16;
layout(constant_id = DACRT_SPEC_MAX_DEPTH) const uint kMaxDepth = 48;
// Loop iterations one slice of a work item may spend (0: no limit, one slice per work item).
layout(constant_id = DACRT_SPEC_LOOP_BUDGET) const uint kLoopBudget = 0;
// Primary rays share their origin and tmin: filters then take them from push constants and
// load only invDir (llvmpipe loads a buffer component one invocation at a time).
layout(constant_id = DACRT_SPEC_SHARED_START) const bool kSharedStart = false;
// Shadow and occlusion rays: a ray ends at its first hit in its segment, wherever it lies.
layout(constant_id = DACRT_SPEC_ANY_HIT) const bool kAnyHit = false;
// Any-hit rays that share their segment [tmin, tmax] (a secondary pass's): a ray leaves the
// traversal at its first hit, so a live ray's best hit is still its start (no hit at tmax), and
// filters and leaves take tmin, tmax and that start from push constants instead of loading them.
layout(constant_id = DACRT_SPEC_SHARED_SEGMENT) const bool kSharedSegmentSpec = false;
const bool kSharedSegment = kSharedSegmentSpec && kAnyHit;
// Nonzero: a node whose leaf would cost more than this many splits splits on (dacrt.comp,
// leafCostsMoreThanSplits). 0: the leaf limits and stalled splits alone decide.
layout(constant_id = DACRT_SPEC_LEAF_OVER_SPLIT) const uint kLeafOverSplit = 0;
// The workgroup is one subgroup, which the device runs as the lanes of one SIMD thread
// (llvmpipe): its invocations cannot be out of step, so memory barriers alone order its loads
// and stores, and the kernel specializes to one without any execution barrier. On llvmpipe a
// kernel with barriers runs as a coroutine that each barrier suspends, and one without them
// does not. false (the default): every barrier is kept, as a GPU whose lanes may diverge needs.
layout(constant_id = DACRT_SPEC_LOCKSTEP_SUBGROUPS) const bool kLockstepSubgroups = false;
// Nonzero: a node is also a leaf where its ray/triangle tests number fewer than this many per
// id a split would partition (leafUnderBalance, shaders/leaf_rule.glsl). 0: off.
layout(constant_id = DACRT_SPEC_LEAF_BALANCE) const uint kLeafBalance = 0;
// Nonzero: primary rays travel the top of the tree as packets of 8x8 pixels (shaders/
// ray_packets.glsl), and a node with fewer than this many packets goes on ray by ray. 0: off.
layout(constant_id = DACRT_SPEC_PACKET_FLUSH) const uint kPacketFlush = 0;
// Nonzero: a node whose rays number at least this many times its triangles traces in its cell
// cut to its triangles' bounds, widened by the margin (dacrt.comp, tightenBox). 0: off.
layout(constant_id = DACRT_SPEC_TIGHT_BOX_RAYS) const uint kTightBoxRays = 2;

#ifdef DACRT_ADDRESSED
// Arrays larger than one binding may be (maxStorageBufferRange) are reached by device address,
// in chunks of kChunkBytes (the last one shorter), each its own allocation: an element's chunk
// and place come from its index, with a division by a constant once specialized. The host
// plans the chunks (host/gpu/binding_set.cpp) and writes their addresses to the chunk table.
// kChunkBytes 0: every array is one chunk, whose address each invocation reads once.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
layout(constant_id = DACRT_SPEC_CHUNK_BYTES) const uint kChunkBytes = 0;
const uint kChunkDivisor = kChunkBytes == 0u ? DACRT_CHUNK_ALIGNMENT : kChunkBytes;
layout(std430, binding = DACRT_BINDING_ADDRESSES) readonly buffer ChunkTable {
    uint firstChunk[DACRT_ADDRESSED_ARRAYS];
    uvec2 chunkAddresses[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer RayChunk { Ray v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer TriangleChunk { Triangle v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BoundsChunk { Bounds v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer HitChunk { Hit v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) coherent buffer IdChunk { uint v[]; };
uvec2 gArrayBase[DACRT_ADDRESSED_ARRAYS];  // each array's first chunk
void loadArrayBases() {
    for (uint a = 0u; a < DACRT_ADDRESSED_ARRAYS; ++a) gArrayBase[a] = chunkAddresses[firstChunk[a]];
}
uvec2 chunkAddress(uint array, uint chunk) {
    return kChunkBytes == 0u ? gArrayBase[array] : chunkAddresses[firstChunk[array] + chunk];
}
// Element i of an addressed array (an lvalue); i is read twice, so it must have no side effects.
#define DACRT_CHUNKED(Chunk, array, elementBytes, i) \
    Chunk(chunkAddress(array, (i) / (kChunkDivisor / elementBytes))) \
        .v[kChunkBytes == 0u ? (i) : (i) % (kChunkDivisor / elementBytes)]
#define RAYS(i) DACRT_CHUNKED(RayChunk, DACRT_ARRAY_RAYS, 64u, i)
#define TRIANGLES(i) DACRT_CHUNKED(TriangleChunk, DACRT_ARRAY_TRIANGLES, 48u, i)
#define TRIANGLE_BOUNDS(i) DACRT_CHUNKED(BoundsChunk, DACRT_ARRAY_TRIANGLE_BOUNDS, 32u, i)
#define HITS(i) DACRT_CHUNKED(HitChunk, DACRT_ARRAY_HITS, 16u, i)
#define RAY_IDS(i) DACRT_CHUNKED(IdChunk, DACRT_ARRAY_RAY_IDS, 4u, i)
#define TRI_IDS(i) DACRT_CHUNKED(IdChunk, DACRT_ARRAY_TRI_IDS, 4u, i)
#define SOURCE_RAYS(i) DACRT_CHUNKED(RayChunk, DACRT_ARRAY_SOURCE_RAYS, 64u, i)
#define SOURCE_HITS(i) DACRT_CHUNKED(HitChunk, DACRT_ARRAY_SOURCE_HITS, 16u, i)
#else
// Rays are read-only but where a kernel makes them (secondary.comp defines DACRT_MAKES_RAYS).
#ifdef DACRT_MAKES_RAYS
layout(std430, binding = DACRT_BINDING_RAYS) writeonly buffer RayBuffer { Ray rays[]; };
#else
layout(std430, binding = DACRT_BINDING_RAYS) readonly buffer RayBuffer { Ray rays[]; };
#endif
layout(std430, binding = DACRT_BINDING_TRIANGLES) readonly buffer TriangleBuffer { Triangle triangles[]; };
layout(std430, binding = DACRT_BINDING_TRIANGLE_BOUNDS) readonly buffer BoundsBuffer { Bounds triangleBounds[]; };
layout(std430, binding = DACRT_BINDING_HITS) coherent buffer HitBuffer { Hit hits[]; };
// Id arrays with scratch space behind them: one buffer each, so that a partition writes every
// id with one store, kept or dropped (llvmpipe runs a store one invocation at a time, both
// sides of a branch included).
layout(std430, binding = DACRT_BINDING_RAY_IDS) coherent buffer RayIdBuffer { uint rayIds[]; };
layout(std430, binding = DACRT_BINDING_TRI_IDS) coherent buffer TriIdBuffer { uint triIds[]; };
layout(std430, binding = DACRT_BINDING_SOURCE_RAYS) readonly buffer SourceRayBuffer { Ray sourceRays[]; };
layout(std430, binding = DACRT_BINDING_SOURCE_HITS) readonly buffer SourceHitBuffer { Hit sourceHits[]; };
// The same elements as the addressed kernels name them.
#define RAYS(i) rays[i]
#define TRIANGLES(i) triangles[i]
#define TRIANGLE_BOUNDS(i) triangleBounds[i]
#define HITS(i) hits[i]
#define RAY_IDS(i) rayIds[i]
#define TRI_IDS(i) triIds[i]
#define SOURCE_RAYS(i) sourceRays[i]
#define SOURCE_HITS(i) sourceHits[i]
void loadArrayBases() {}
#endif
layout(std430, binding = DACRT_BINDING_REGIONS) coherent buffer RegionBuffer { Region regions[]; };
layout(std430, binding = DACRT_BINDING_WORK_ITEMS) readonly buffer WorkItemBuffer { WorkItem workItems[]; };
layout(std430, binding = DACRT_BINDING_COUNTERS) coherent buffer CounterBuffer { GpuCounters counters; };
layout(std430, binding = DACRT_BINDING_STATES) coherent buffer StateBuffer { TraversalState states[]; };
layout(std430, binding = DACRT_BINDING_STACKS) coherent buffer StackBuffer { StackEntry stacks[]; };
layout(std430, binding = DACRT_BINDING_PACKETS) readonly buffer PacketBuffer { PacketBounds packets[]; };

// Frame parameters, set from push constants at the start of main.
float gMargin;
vec3 gRayOrigin;
float gRayTmin;
float gRayTmax;       // kSharedSegment
uint gAxis;
uint gOrder;         // kOrder*
uint gRayScratchHalf;
uint gTriScratchHalf;
uint gPacketRaysAt;  // DacrtPush's packet sections of the ray id buffer
uint gDoneFlagsAt;
uint gPacketIdsAt;
uint gPacketCount;

const uint kWorkgroupSize = gl_WorkGroupSize.x;

shared uint sSubgroupTotals[kWorkgroupSize];
shared uint sBoxKeys[6];                     // triangleBoundsBox: orderedKey minima, then maxima
shared bool sReady;                           // this work item may run now
// The DACRT stack of the running slice (saved to `stacks` between slices): a split pushes one
// waiting child, or two where rays are classified per split (kOrderPerRay).
const uint kStackCapacity = 2u * kMaxDepth + 1u;
shared StackEntry sStack[kStackCapacity];
shared uint sStackSlot;                       // the slot a work item's first save takes

#endif
