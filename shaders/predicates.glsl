// Geometric predicates shared by every backend. This file is valid GLSL and, through
// host/shader_compat.hpp, valid C++: a fix here reaches the CPU and the GPU at once.
// Rules (docs/correctness.md): filters may say "maybe" wrongly but never "no" wrongly;
// arithmetic is IEEE single precision with no contraction (precise / -ffp-contract=off).
#ifndef DACRT_PREDICATES_GLSL
#define DACRT_PREDICATES_GLSL

const uint kMissPrim = 0xFFFFFFFFu;
const float kNoHitT = 3.402823466e+38;          // FLT_MAX: finite, so no inf arithmetic anywhere
// 2 * gamma(3), gamma(n) = n u / (1 - n u), u = 2^-24 (Pharr, Jakob, Humphreys; Ize 2013):
// the relative error bound of (bound - origin) * invDir, doubled to absorb the rounding of
// the widening itself.
const float kSlabSlack = 3.5762809e-07;

struct RayInterval {
    float tNear;
    float tFar;
};

// The interval of one slab lo <= origin + t dir <= hi, widened outward. A zero direction
// component never divides: the slab then either holds the origin (no constraint) or the
// interval is empty. With |invDir| >= 1 and finite operands nothing here can become NaN.
RayInterval slabInterval(float origin, float dir, float invDir, float lo, float hi) {
    precise float t0 = (lo - origin) * invDir;
    precise float t1 = (hi - origin) * invDir;
    precise float enter = min(t0, t1);
    precise float leave = max(t0, t1);
    RayInterval r;
    r.tNear = enter - abs(enter) * kSlabSlack;
    r.tFar = leave + abs(leave) * kSlabSlack;
    if (dir == 0.0) {
        bool inside = origin >= lo && origin <= hi;
        r.tNear = inside ? -kNoHitT : kNoHitT;
        r.tFar = inside ? kNoHitT : -kNoHitT;
    }
    return r;
}

// Parametric interval of a ray inside [lo, hi], containing the exact interval of the float
// ray; empty when tNear > tFar.
RayInterval rayBoxInterval(IN(Ray) ray, vec3 lo, vec3 hi) {
    RayInterval x = slabInterval(ray.origin.x, ray.dir.x, ray.invDir.x, lo.x, hi.x);
    RayInterval y = slabInterval(ray.origin.y, ray.dir.y, ray.invDir.y, lo.y, hi.y);
    RayInterval z = slabInterval(ray.origin.z, ray.dir.z, ray.invDir.z, lo.z, hi.z);
    RayInterval r;
    r.tNear = max(x.tNear, max(y.tNear, z.tNear));
    r.tFar = min(x.tFar, min(y.tFar, z.tFar));
    return r;
}

// May the ray meet the box at some t in [tmin, tmax]? (tmax inclusive: equal-t ties matter.)
bool rayMayCrossBox(IN(Ray) ray, vec3 lo, vec3 hi, float tmax) {
    RayInterval r = rayBoxInterval(ray, lo, hi);
    return r.tNear <= r.tFar && r.tFar >= ray.tmin && r.tNear <= tmax;
}

// Acceptance rule: a hit at t may end the ray in this box only if t is no later than the
// (upper bound of the) exit parameter.
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

// Watertight ray/triangle test (Woop, Benthin, Wald 2013) in single precision, without the
// double-precision fallback so that every backend runs the same arithmetic. Edge values of
// a shared edge are exact negations of each other (a*b - c*d versus c*d - a*b), and zero
// counts as inside, so no ray passes between two triangles that share an edge.
// Degenerate (zero-area or edge-on) triangles give det == 0 and never hit.
TriangleHit intersectWatertight(IN(Ray) ray, vec3 p0, vec3 p1, vec3 p2) {
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
    precise float az = ray.shear.z * a[kz];
    precise float bz = ray.shear.z * b[kz];
    precise float cz = ray.shear.z * c[kz];
    precise float tScaled = eu * az + ev * bz + ew * cz;
    if (det > 0.0 ? tScaled <= 0.0 : tScaled >= 0.0) return h;
    h.hit = true;
    h.t = tScaled / det;
    h.u = ev / det;
    h.v = ew / det;
    return h;
}

// The tie rule of every backend: smaller t wins; equal t goes to the smaller primitive id.
bool hitPrecedes(float t, uint prim, float bestT, uint bestPrim) {
    return t < bestT || (t == bestT && prim < bestPrim);
}

#endif
