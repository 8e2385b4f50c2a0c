#version 450
// Runs one building block of dacrt.comp (a stable partition or a leaf) in one workgroup, so
// that tests can compare it with the CPU on random inputs.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#define IN(T) in T
#include "layout.h"
#include "predicates.glsl"
#include "dacrt_bindings.glsl"
#include "dacrt_workgroup.glsl"

layout(push_constant) uniform Push { WorkgroupTestPush push; };

void main() {
    gMargin = 0.0;
    gRayOrigin = vec3(0.0);
    gAxis = push.axis;
    gRayScratchHalf = push.rayScratchHalf;
    gTriScratchHalf = push.triScratchHalf;
    uint result;
    if (push.mode == 0u) result = partitionRays(push.begin, push.end, push.rule, push.lo, push.hi);
    else if (push.mode == 1u) result = partitionTriangles(push.begin, push.end, push.lo, push.hi);
    else result = leaf(push.lo, push.hi, push.begin, push.end, push.triBegin, push.triEnd);
    bool cutShort = loopLimiterFired(2u + push.pad0);
    if (gl_LocalInvocationIndex == 0) {
        counters.testResult = result;
        if (cutShort) counters.loopLimitHits = 1u;
    }
}
