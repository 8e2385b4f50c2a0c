#version 460
// The rayquery backend: the driver's own ray tracing (VK_KHR_ray_query) over a BLAS of the
// frame's triangles, one invocation per ray, writing the same Hit records as the DACRT kernel.
// The peer a Vulkan user would pick; not watertight by specification, so `dacrt bench`
// measures its error like any other backend's.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_ray_query : require

#define IN(T) in T
#include "layout.h"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer RayBuffer { Ray rays[]; };
layout(std430, binding = 1) writeonly buffer HitBuffer { Hit hits[]; };
layout(binding = 2) uniform accelerationStructureEXT scene;
layout(std430, binding = 3) readonly buffer TriangleBuffer { Triangle triangles[]; };  // the BLAS's vertices

layout(push_constant) uniform Push {
    uint rayCount;
    uint firstRay;
    uint cullBackFaces;  // 1: some triangles are single-sided (Triangle::cullBackFace)
    uint anyHit;         // 1: any hit in the segment will do (HitQuery::Any: shadow and occlusion rays)
} push;

void main() {
    uint i = push.firstRay + gl_GlobalInvocationID.x;
    if (i >= push.rayCount) return;
    Ray ray = rays[i];
    rayQueryEXT query;
    // Opaque: every hit found is committed, no any-hit shaders. With single-sided triangles
    // (dacrt's face rule), every candidate comes back here and is confirmed unless it is one's
    // back face: per triangle, which the ray flag gl_RayFlagsCullBackFacingTrianglesEXT is not
    // (and lavapipe, Mesa 25.0.7, ignores that flag: docs/skips.md). For any hit, the traversal
    // ends at the first hit committed, so the face rule holds there too.
    bool cull = push.cullBackFaces != 0u;
    uint flags = cull ? gl_RayFlagsNoOpaqueEXT : gl_RayFlagsOpaqueEXT;
    if (push.anyHit != 0u) flags |= gl_RayFlagsTerminateOnFirstHitEXT;
    rayQueryInitializeEXT(query, scene, flags, 0xFFu, ray.origin, ray.tmin, ray.dir, ray.tmax);
    while (rayQueryProceedEXT(query)) {
        if (rayQueryGetIntersectionTypeEXT(query, false) != gl_RayQueryCandidateIntersectionTriangleEXT) continue;
        uint prim = uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, false));
        if (triangles[prim].cullBackFace == 0u || rayQueryGetIntersectionFrontFaceEXT(query, false))
            rayQueryConfirmIntersectionEXT(query);
    }
    Hit h;
    h.t = ray.tmax;  // a miss, as every backend reports it (missHit)
    h.prim = kMissPrim;
    h.u = 0.0;
    h.v = 0.0;
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        h.t = rayQueryGetIntersectionTEXT(query, true);
        h.prim = uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, true));
        vec2 uv = rayQueryGetIntersectionBarycentricsEXT(query, true);  // weights of v1 and v2, as dacrt's
        h.u = uv.x;
        h.v = uv.y;
    }
    hits[i] = h;
}
