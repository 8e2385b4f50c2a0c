#version 450
// Runs one building block of dacrt.comp (a stable partition or a leaf) in one workgroup, so
// that tests can compare it with the CPU on random inputs.
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

layout(push_constant) uniform Push { WorkgroupTestPush push; };

void main() {
    gMargin = 0.0;
    gRayOrigin = vec3(0.0);
    gRayTmin = 0.0;
    gAxis = push.axis;
    gRayScratchHalf = push.rayScratchHalf;
    gTriScratchHalf = push.triScratchHalf;
    uint result;
    // One call site per rule, each with a constant rule, as in dacrt.comp (a rule known only at
    // run time would make every branch of the predicate run under a mask).
    if (push.mode == 0u && push.rule == kKeepCrossing) result = partitionRays(push.begin, push.end, kKeepCrossing, push.lo, push.hi);
    else if (push.mode == 0u && push.rule == kKeepFinished) result = partitionRays(push.begin, push.end, kKeepFinished, push.lo, push.hi);
    else if (push.mode == 0u && push.rule == kKeepStill) result = partitionRays(push.begin, push.end, kKeepStill, push.lo, push.hi);
    else if (push.mode == 0u && push.rule == kKeepStuckHigh) result = partitionRays(push.begin, push.end, kKeepStuckHigh, push.lo, push.hi);
    else if (push.mode == 0u) result = partitionRays(push.begin, push.end, kKeepStuckLow, push.lo, push.hi);
    else if (push.mode == 1u) result = partitionTriangles(push.begin, push.end, push.lo, push.hi);
    else result = leaf(push.lo, push.hi, push.begin, push.end, push.triBegin, push.triEnd);
    bool cutShort = loopLimiterFired(push.loopProbe);
    if (gl_LocalInvocationIndex == 0) {
        counters.testResult = result;
        if (cutShort) counters.loopLimitHits = 1u;
    }
}
