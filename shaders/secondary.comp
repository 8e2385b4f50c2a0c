#version 450
// A secondary pass on the device, from the primary pass's rays and hits, which never leave it:
// step 0 makes each slot's ray (shaders/secondary_rays.glsl, the host's code bit for bit) and
// counts the rays of each region slot; step 1 turns the counts into ray ranges; step 2 writes
// each ray's id into its slot's range. The DACRT kernel then traces them.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require

#define IN(T) in T
#define DACRT_UNROLL [[unroll]]
#define DACRT_MAKES_RAYS
#include "layout.h"
#include "predicates.glsl"
#include "secondary_rays.glsl"
#include "dacrt_bindings.glsl"

layout(push_constant) uniform Push { SecondaryPush push; };

const uint kNoSlot = 0xFFFFFFFFu;

// The region a ray meets first, as divideScene bins rays on the host (scene_division.cpp):
// none if it misses the widened scene box; else from one slab behind the origin's, so that
// rounding never skips the true first one, the first widened slab it may cross, walking the way
// it travels along the axis. Region k's box is its first slot's (k * groups).
uint firstRegion(Ray ray) {
    uint n = push.regionCount;
    uint last = (n - 1u) * push.groups;
    vec3 margin = vec3(push.margin);
    if (!rayMayCrossCell(ray, regions[0].lo - margin, regions[last].hi + margin, kNoHitT)) return kNoSlot;
    uint axis = push.axis;
    float o = ray.origin[axis];
    float d = ray.dir[axis];
    int travel = d < 0.0 ? -1 : 1;
    int holding = 0;  // the slab holding o: the boundaries at or below it
    for (uint k = 1u; k < n; ++k) holding += regions[k * push.groups].lo[axis] <= o ? 1 : 0;
    int k = holding - travel;
    if (d > 0.0 && o < regions[0].lo[axis]) k = 0;
    if (d < 0.0 && o > regions[last].hi[axis]) k = int(n) - 1;
    k = clamp(k, 0, int(n) - 1);
    for (; k >= 0 && k < int(n); k += travel) {
        Region r = regions[uint(k) * push.groups];
        if (rayMayCrossCell(ray, r.lo - margin, r.hi + margin, kNoHitT)) return uint(k);
    }
    return kNoSlot;
}

// Step 0, one invocation per slot (source ray s, sample k): its ray, its starting hit, and its
// slot (region and ray group: the rays of the g-th band of the image go to group g), counted
// in each slot's rayEnd, with the directions they move along the axis; a ray that meets no
// region is counted as culled, as the host's division counts those it drops. One ray an
// invocation keeps its loops (16 tries, two walks over at most 4096 regions) far below
// llvmpipe's 65535.
void makeRay(uint slot) {
    uint source = slot / push.raysPerHit;
    uint k = slot - source * push.raysPerHit;
    Hit primaryHit = SOURCE_HITS(source);
    SurfaceSample surface = noSurface();
    if (primaryHit.prim != kMissPrim) surface = surfaceOfHit(SOURCE_RAYS(source), primaryHit, TRIANGLES(primaryHit.prim));
    uint band = (push.sourceCount + push.groups - 1u) / push.groups;
    uint group = min(source / band, push.groups - 1u);
    uint stream = source * push.samplesPerHit + push.firstSample + k;
    GeneratedRay g = push.kind == kPassShadow ? shadowRay(surface, push.light)
                                              : occlusionRay(surface, stream, push.sampleSeed, push.occlusionDistance);
    RAYS(slot) = g.ray;
    Hit start;
    start.t = g.traced ? g.ray.tmax : 0.0;
    start.prim = g.traced ? kMissPrim : kNotTracedPrim;
    start.u = 0.0;
    start.v = 0.0;
    HITS(slot) = start;
    uint region = g.traced ? firstRegion(g.ray) : kNoSlot;
    uint key = region == kNoSlot ? kNoSlot : region * push.groups + group;
    RAY_IDS(gRayScratchHalf + slot) = key;
    if (g.traced && key == kNoSlot) atomicAdd(counters.raysCulled, 1u);
    if (key == kNoSlot) return;
    atomicAdd(regions[key].rayEnd, 1u);
    float d = g.ray.dir[push.axis];
    uint moving = (d < 0.0 ? kTowardLow : 0u) | (d > 0.0 ? kTowardHigh : 0u);
    if (moving != 0u) atomicOr(regions[key].directions, moving);
}

// Step 1, one invocation: counts to consecutive ranges, slot by slot.
void rangesFromCounts() {
    uint next = 0u;
    uint slots = push.regionCount * push.groups;
    for (uint j = 0u; j < slots; ++j) {
        uint count = regions[j].rayEnd;
        regions[j].rayBegin = next;
        regions[j].terminated = next;
        regions[j].cursor = next;
        next += count;
        regions[j].rayEnd = next;
    }
}

// Step 2, one invocation per ray slot: its id into its region slot's range (in no particular
// order: no result depends on the order of a range's rays).
void writeRayId(uint slot) {
    uint key = RAY_IDS(gRayScratchHalf + slot);
    if (key == kNoSlot) return;
    uint place = atomicAdd(regions[key].cursor, 1u);
    RAY_IDS(place) = slot;
}

void main() {
    gRayScratchHalf = push.sourceCount * push.raysPerHit;
    loadArrayBases();
    uint i = push.firstInvocation + gl_GlobalInvocationID.x;
    if (push.step == 0u && i < gRayScratchHalf) makeRay(i);
    if (push.step == 1u && i == 0u) rangesFromCounts();
    if (push.step == 2u && i < gRayScratchHalf) writeRayId(i);
}
