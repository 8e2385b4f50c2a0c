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
layout(std430, binding = DACRT_BINDING_REGIONS) coherent buffer RegionBuffer { Region regions[]; };
layout(std430, binding = DACRT_BINDING_WORK_ITEMS) readonly buffer WorkItemBuffer { WorkItem workItems[]; };
layout(std430, binding = DACRT_BINDING_COUNTERS) coherent buffer CounterBuffer { GpuCounters counters; };
layout(std430, binding = DACRT_BINDING_STATES) coherent buffer StateBuffer { TraversalState states[]; };
layout(std430, binding = DACRT_BINDING_STACKS) coherent buffer StackBuffer { StackEntry stacks[]; };
layout(std430, binding = DACRT_BINDING_SOURCE_RAYS) readonly buffer SourceRayBuffer { Ray sourceRays[]; };
layout(std430, binding = DACRT_BINDING_SOURCE_HITS) readonly buffer SourceHitBuffer { Hit sourceHits[]; };

// Frame parameters, set from push constants at the start of main.
float gMargin;
vec3 gRayOrigin;
float gRayTmin;
uint gAxis;
uint gOrder;         // kOrder*
uint gRayScratchHalf;
uint gTriScratchHalf;

const uint kWorkgroupSize = gl_WorkGroupSize.x;

shared uint sSubgroupTotals[kWorkgroupSize];
shared bool sReady;                           // this work item may run now
// The DACRT stack of the running slice (saved to `stacks` between slices): a split pushes one
// waiting child, or two where rays are classified per split (kOrderPerRay).
const uint kStackCapacity = 2u * kMaxDepth + 1u;
shared StackEntry sStack[kStackCapacity];
shared uint sStackSlot;                       // the slot a work item's first save takes

#endif
