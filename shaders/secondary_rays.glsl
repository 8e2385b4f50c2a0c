// Secondary rays from primary hits: the surface point and normal, the origin offset off the
// surface, shadow rays towards a light and cosine-distributed occlusion rays. Valid GLSL and,
// through host/dacrt/secondary_rays.hpp, valid C++: the host (cpu backends, peers) and the
// device (gpu backend, shaders/secondary.comp) make the same rays bit for bit. Arithmetic is
// IEEE single precision with no contraction (precise / -ffp-contract=off); division and
// square root are exact_math.glsl's correctly rounded ones; float literals carry an f so
// that C++ computes in float too.
#ifndef DACRT_SECONDARY_RAYS_GLSL
#define DACRT_SECONDARY_RAYS_GLSL

#include "exact_math.glsl"

// 2^-64: direction components below it are flushed to zero, as makeRay does, so that every
// 1/dir stays below 2^64 (predicates.glsl's slab bounds stay finite).
const float kSmallestDirection = 5.421010862427522e-20f;
// 2^-100: the smallest coordinate magnitude whose float32 step the origin offset takes, so
// that the step is a normal float.
const float kSmallestReach = 7.888609052210118e-31f;
// The most float32 steps the origin offset moves a coordinate (Wachter and Binder's int_scale).
const float kOffsetSteps = 256.0f;

float dot3(vec3 a, vec3 b) {
    precise float d = a.x * b.x + a.y * b.y + a.z * b.z;
    return d;
}

// Where every secondary ray's segment starts (the kernel takes it once: DACRT_SPEC_SHARED_SEGMENT).
const float kSegmentStart = 0.0f;

// The ray from origin along direction (of any length, not normalized), hits in (0, tmax]:
// makeRay's rules (flush below 2^-64, the watertight permutation and shear) with exact
// division. The direction must have a component of at least 2^-64 and at most 2^62.
Ray segmentRay(vec3 origin, vec3 direction, float tmax) {
    vec3 d = direction;
    if (abs(d.x) < kSmallestDirection) d.x = 0.0f;
    if (abs(d.y) < kSmallestDirection) d.y = 0.0f;
    if (abs(d.z) < kSmallestDirection) d.z = 0.0f;
    Ray r;
    r.origin = origin;
    r.tmin = kSegmentStart;
    r.dir = d;
    r.tmax = tmax;
    r.invDir = vec3(d.x == 0.0f ? 0.0f : divideRounded(1.0f, d.x), d.y == 0.0f ? 0.0f : divideRounded(1.0f, d.y),
                    d.z == 0.0f ? 0.0f : divideRounded(1.0f, d.z));
    int kz = 0;
    if (abs(d.y) > abs(d[kz])) kz = 1;
    if (abs(d.z) > abs(d[kz])) kz = 2;
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) {  // keeps the winding, so the sign of det is the facing
        int swap = kx;
        kx = ky;
        ky = swap;
    }
    r.axes = uint(kx) | (uint(ky) << 2u) | (uint(kz) << 4u);
    r.shear = vec3(divideRounded(d[kx], d[kz]), divideRounded(d[ky], d[kz]), r.invDir[kz]);  // 1/d[kz] once
    r.pad1 = 0.0f;
    return r;
}

// Wachter and Binder's origin offset ("A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems, 2019): each coordinate moves along the normal by
// kOffsetSteps times the normal's component float32 steps (truncated: none where that is below
// one), the steps counted at `reach`. Their steps are each coordinate's own; here they are those
// of the largest coordinate magnitude among the point and the triangle's vertices, on every
// axis, because the rounding that could bring the ray back is of that size: the barycentric
// point's grows with the vertices (a point near 0 on a large triangle is not known to 0's
// precision), and the watertight test mixes the axes (a triangle in the plane y = 0 is met with
// the rounding of its x and z). No absolute offset is needed near the origin: nothing here
// depends on the scene's scale.
float offsetCoordinate(float p, float n, float reach) {
    int steps = int(kOffsetSteps * n);
    float r = max(reach, kSmallestReach);
    uint e = (floatBitsToUint(r) >> 23u) & 0xFFu;
    float stepSize = uintBitsToFloat((e - 23u) << 23u);  // 2^(e - 150): one float32 step at r
    precise float moved = p + float(steps) * stepSize;
    return moved;
}

// The surface a primary ray hit, as secondary rays leave it.
struct SurfaceSample {
    vec3 point;    // on the triangle, from the hit's barycentrics
    vec3 normal;   // the triangle's unit geometric normal, on the side the primary ray came from
    vec3 origin;   // point moved off the surface along normal: where secondary rays start
    bool valid;    // false for a miss
};

float largestMagnitude(float a, float b, float c, float d) {
    return max(max(abs(a), abs(b)), max(abs(c), abs(d)));
}

SurfaceSample noSurface() {
    SurfaceSample s;
    s.point = vec3(0.0f);
    s.normal = vec3(0.0f);
    s.origin = vec3(0.0f);
    s.valid = false;
    return s;
}

// tri is the hit's triangle (anything for a miss).
SurfaceSample surfaceOfHit(IN(Ray) primary, IN(Hit) hit, IN(Triangle) tri) {
    SurfaceSample s = noSurface();
    if (hit.prim == kMissPrim || hit.prim == kNotTracedPrim) return s;
    precise float w = 1.0f - hit.u - hit.v;
    precise vec3 p = tri.v0 * w + tri.v1 * hit.u + tri.v2 * hit.v;
    precise vec3 e1 = tri.v1 - tri.v0;
    precise vec3 e2 = tri.v2 - tri.v0;
    precise vec3 n = vec3(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
    // A hit triangle has area in float32 (triangleHasNoArea); one whose cross product is
    // subnormal (edges below 1e-19) has no normal float32 can normalize.
    if (!(max(abs(n.x), max(abs(n.y), abs(n.z))) >= 1.1754943508222875e-38f)) return s;
    vec3 unit = normalizeRounded(n);
    if (dot3(unit, primary.dir) > 0.0f) unit = -unit;
    float reach = max(max(largestMagnitude(p.x, tri.v0.x, tri.v1.x, tri.v2.x),
                          largestMagnitude(p.y, tri.v0.y, tri.v1.y, tri.v2.y)),
                      largestMagnitude(p.z, tri.v0.z, tri.v1.z, tri.v2.z));
    s.point = p;
    s.normal = unit;
    s.origin = vec3(offsetCoordinate(p.x, unit.x, reach), offsetCoordinate(p.y, unit.y, reach),
                    offsetCoordinate(p.z, unit.z, reach));
    s.valid = true;
    return s;
}

struct GeneratedRay {
    Ray ray;
    bool traced;  // false: the slot has no ray (kNotTracedPrim)
};

GeneratedRay noRay() {
    GeneratedRay g;
    g.ray = segmentRay(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), 0.0f);
    g.traced = false;
    return g;
}

// Where a shadow ray's segment ends: at the light (t = 1 on the segment to it), or nowhere for a
// directional light. Every shadow ray of a light shares it, as every occlusion ray of a pass
// shares its length.
float shadowSegmentEnd(IN(ShadowLight) light) {
    return light.type == kLightDirectional ? kNoHitT : 1.0f;
}

// The shadow ray of a surface towards a light: to a point or spot light the segment up to it
// (t in (0, 1]), to a directional light the whole ray against its direction. None where the
// light cannot reach the surface: the surface faces away from it (in shadow without a ray),
// or the point lies beyond the light's range or outside a spot's outer cone (compared
// squared, so that no square root is needed).
GeneratedRay shadowRay(IN(SurfaceSample) s, IN(ShadowLight) light) {
    if (!s.valid) return noRay();
    bool directional = light.type == kLightDirectional;
    precise vec3 toLight = directional ? -light.direction : light.position - s.point;
    if (!(dot3(s.normal, toLight) > 0.0f)) return noRay();
    if (!directional) {
        float distanceSquared = dot3(toLight, toLight);
        precise float rangeSquared = light.range * light.range;
        if (light.range > 0.0f && distanceSquared > rangeSquared) return noRay();
        if (light.type == kLightSpot) {
            float along = -dot3(light.direction, toLight);
            precise float alongSquared = along * along;
            precise float coneSquared = light.cosOuterSquared * distanceSquared;
            if (!(along > 0.0f) || alongSquared < coneSquared) return noRay();
        }
    }
    precise vec3 direction = directional ? -light.direction : light.position - s.origin;
    if (max(abs(direction.x), max(abs(direction.y), abs(direction.z))) < kSmallestDirection) return noRay();
    GeneratedRay g;
    g.ray = segmentRay(s.origin, direction, shadowSegmentEnd(light));
    g.traced = true;
    return g;
}

// Occlusion ray number `stream` (primary ray index * samples per hit + sample) of a surface: Malley's
// method, a point uniform in the unit disk lifted to the hemisphere about the normal, which is
// cosine-distributed. The disk point comes from rejection sampling of the square with the PCG
// hash of the stream number and the pass's seed (16 tries, then the pole: a chance of 2e-11); the
// tangent frame is Duff et al.'s ("Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017).
// The direction is unit up to rounding, so t is a distance and the segment ends at segmentLength.
GeneratedRay occlusionRay(IN(SurfaceSample) s, uint stream, uint seed, float segmentLength) {
    if (!s.valid) return noRay();
    uint hashed = pcgHash(stream ^ pcgHash(seed));
    float x = 0.0f;
    float y = 0.0f;
    float rr = 0.0f;
    for (uint attempt = 0u; attempt < 16u; ++attempt) {
        precise float cx = 2.0f * unitInterval(pcgHash(hashed + 2u * attempt)) - 1.0f;
        precise float cy = 2.0f * unitInterval(pcgHash(hashed + 2u * attempt + 1u)) - 1.0f;
        precise float cr = cx * cx + cy * cy;
        if (cr < 1.0f) {
            x = cx;
            y = cy;
            rr = cr;
            break;
        }
    }
    precise float zz = 1.0f - rr;
    float z = sqrtRounded(zz);
    vec3 n = s.normal;
    float side = n.z >= 0.0f ? 1.0f : -1.0f;
    precise float sum = side + n.z;
    float a = divideRounded(-1.0f, sum);
    precise float b = n.x * n.y * a;
    precise vec3 tangent = vec3(1.0f + side * n.x * n.x * a, side * b, -side * n.x);
    precise vec3 bitangent = vec3(b, side + n.y * n.y * a, -n.y);
    precise vec3 direction = tangent * x + bitangent * y + n * z;
    GeneratedRay g;
    g.ray = segmentRay(s.origin, direction, segmentLength);
    g.traced = true;
    return g;
}

#endif
