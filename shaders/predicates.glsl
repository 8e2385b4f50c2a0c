// Geometric predicates shared by every backend. This file is valid GLSL and, through
// host/dacrt/predicates.hpp, valid C++: a fix here reaches the CPU and the GPU at once.
// Rules (docs/correctness.md): filters may say "maybe" wrongly but never "no" wrongly;
// arithmetic is IEEE single precision with no contraction (precise / -ffp-contract=off).
#ifndef DACRT_PREDICATES_GLSL
#define DACRT_PREDICATES_GLSL

#include "triangle_rules.glsl"

// 2 * gamma(3), gamma(n) = n u / (1 - n u), u = 2^-24 (Pharr, Jakob, Humphreys; Ize 2013):
// the relative error bound of (bound - origin) * invDir, doubled to absorb the rounding of
// the widening itself.
const float kSlabSlack = 3.5762809e-07;

struct RayInterval {
    float tNear;
    float tFar;
};

// The interval of one slab lo <= origin + t dir <= hi, each bound within three roundings of
// the exact one. A zero direction component never divides: the slab then either holds the
// origin (no constraint) or the interval is empty. makeRay keeps |invDir| <= 2^64 and
// coordinates are at most 1e9, so every bound is finite: no inf, no NaN. invDir is 0
// exactly where dir is 0 (makeRay flushes |dir| < 2^-64 to 0, so 1/dir never overflows), so
// the test reads invDir only: a filter on the gpu then loads 3 floats of the ray, not 6.
RayInterval slabInterval(float origin, float invDir, float lo, float hi) {
    precise float t0 = (lo - origin) * invDir;
    precise float t1 = (hi - origin) * invDir;
    RayInterval r;
    r.tNear = min(t0, t1);
    r.tFar = max(t0, t1);
    if (invDir == 0.0) {
        bool inside = origin >= lo && origin <= hi;
        r.tNear = inside ? -kNoHitT : kNoHitT;
        r.tFar = inside ? kNoHitT : -kNoHitT;
    }
    return r;
}

// The rounded interval of a ray inside [lo, hi]; empty when tNear > tFar.
RayInterval rayBoxIntervalRounded(IN(Ray) ray, vec3 lo, vec3 hi) {
    RayInterval x = slabInterval(ray.origin.x, ray.invDir.x, lo.x, hi.x);
    RayInterval y = slabInterval(ray.origin.y, ray.invDir.y, lo.y, hi.y);
    RayInterval z = slabInterval(ray.origin.z, ray.invDir.z, lo.z, hi.z);
    RayInterval r;
    r.tNear = max(x.tNear, max(y.tNear, z.tNear));
    r.tFar = min(x.tFar, min(y.tFar, z.tFar));
    return r;
}

// The interval widened so that it contains the exact interval of the float ray. Widening
// after the min/max equals widening each slab: t - |t| k is monotone for k < 1.
RayInterval rayBoxInterval(IN(Ray) ray, vec3 lo, vec3 hi) {
    RayInterval r = rayBoxIntervalRounded(ray, lo, hi);
    precise float nearLow = r.tNear - abs(r.tNear) * kSlabSlack;
    precise float farHigh = r.tFar + abs(r.tFar) * kSlabSlack;
    r.tNear = nearLow;
    r.tFar = farHigh;
    return r;
}

// Filter: may the ray meet the cell at some t in [tmin, tmax]? (tmax inclusive: equal-t
// ties matter.) Called only with cells already widened by the filter margin, which exceeds
// the rounding of these bounds many times over, so the rounded interval of the widened cell
// contains the exact interval of the cell itself (docs/correctness.md).
bool rayMayCrossCell(IN(Ray) ray, vec3 lo, vec3 hi, float tmax) {
    RayInterval r = rayBoxIntervalRounded(ray, lo, hi);
    return r.tNear <= r.tFar && r.tFar >= ray.tmin && r.tNear <= tmax;
}

// Acceptance rule: a hit at t may end the ray in this (unwidened) box only if t is no later
// than an upper bound of the exact exit parameter.
bool hitEndsInBox(IN(Ray) ray, vec3 lo, vec3 hi, float t) {
    RayInterval r = rayBoxInterval(ray, lo, hi);
    return t <= r.tFar;
}

// Conservative triangle/cell filter: the triangle's bounds overlap the (already widened)
// cell. Pure comparisons, so bit-identical everywhere.
bool boundsOverlap(vec3 aLo, vec3 aHi, vec3 bLo, vec3 bHi) {
    return aLo.x <= bHi.x && aLo.y <= bHi.y && aLo.z <= bHi.z &&
           aHi.x >= bLo.x && aHi.y >= bLo.y && aHi.z >= bLo.z;
}

struct TriangleHit {
    bool hit;
    float t;
    float u;
    float v;
};

// 2^-20: sixteen units in the last place. The sheared vertex coordinates are within a few
// units of their magnitude of the exact ones, so a ray that truly meets the triangle is never
// farther than this from the box of its projected vertices.
const float kProjectionSlack = 9.5367431640625e-07;

// Watertight ray/triangle test (Woop, Benthin, Wald 2013) in single precision, without the
// double-precision fallback so that every backend runs the same arithmetic. Edge values of
// a shared edge are exact negations of each other (a*b - c*d versus c*d - a*b), and zero
// counts as inside, so no ray passes between two triangles that share an edge.
// Never a hit: triangles with no area (triangleHasNoArea), edge-on ones (det == 0), back faces
// of single-sided triangles (backFaceIsCulled: cullBackFace is Triangle::cullBackFace), and those
// whose projection along the ray leaves the ray outside the box of its projected vertices.
// The last happens only through rounding: for a sliver seen nearly end-on, the edge values
// are tiny products' differences whose rounding can pass the sign test while the ray passes
// far from the triangle (docs/correctness.md, "Degenerate and sliver triangles").
TriangleHit intersectWatertight(IN(Ray) ray, vec3 p0, vec3 p1, vec3 p2, bool cullBackFace) {
    TriangleHit h;
    h.hit = false;
    h.t = kNoHitT;
    h.u = 0.0;
    h.v = 0.0;
    int kx = int(ray.axes & 3u);
    int ky = int((ray.axes >> 2) & 3u);
    int kz = int((ray.axes >> 4) & 3u);
    precise vec3 a = p0 - ray.origin;
    precise vec3 b = p1 - ray.origin;
    precise vec3 c = p2 - ray.origin;
    precise float ax = a[kx] - ray.shear.x * a[kz];
    precise float ay = a[ky] - ray.shear.y * a[kz];
    precise float bx = b[kx] - ray.shear.x * b[kz];
    precise float by = b[ky] - ray.shear.y * b[kz];
    precise float cx = c[kx] - ray.shear.x * c[kz];
    precise float cy = c[ky] - ray.shear.y * c[kz];
    precise float eu = cx * by - cy * bx;
    precise float ev = ax * cy - ay * cx;
    precise float ew = bx * ay - by * ax;
    if ((eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0)) return h;
    precise float det = eu + ev + ew;
    if (det == 0.0) return h;
    if (backFaceIsCulled(cullBackFace, det)) return h;
    precise float reach = max(max(max(abs(a.x), abs(a.y)), max(abs(a.z), abs(b.x))),
                              max(max(abs(b.y), abs(b.z)), max(max(abs(c.x), abs(c.y)), abs(c.z))));
    precise float slack = reach * kProjectionSlack;
    if (min(ax, min(bx, cx)) > slack || max(ax, max(bx, cx)) < -slack || min(ay, min(by, cy)) > slack ||
        max(ay, max(by, cy)) < -slack)
        return h;
    if (triangleHasNoArea(p0, p1, p2)) return h;
    precise float az = ray.shear.z * a[kz];
    precise float bz = ray.shear.z * b[kz];
    precise float cz = ray.shear.z * c[kz];
    precise float tScaled = eu * az + ev * bz + ew * cz;
    if (det > 0.0 ? tScaled <= 0.0 : tScaled >= 0.0) return h;
    precise float t = tScaled / det;
    precise float u = ev / det;
    precise float v = ew / det;
    h.hit = true;
    h.t = t;
    h.u = u;
    h.v = v;
    return h;
}

// The tie rule of every backend: smaller t wins; equal t goes to the smaller primitive id.
bool hitPrecedes(float t, uint prim, float bestT, uint bestPrim) {
    return t < bestT || (t == bestT && prim < bestPrim);
}

#endif
