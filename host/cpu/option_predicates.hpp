#pragma once
// Ray/triangle and triangle/box tests that exist only on the CPU: the options the benchmark
// prices (Moller-Trumbore, separating-axis and Mora-style filters, a float64 leaf test) and
// the float64 arithmetic of the reference tracer. The defaults every backend shares live in
// shaders/predicates.glsl.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "cpu/predicates.hpp"
#include "core/shader_layout.hpp"

namespace dacrt {

// Moller-Trumbore (1997) in float32. det == 0 is the only parallel-ray rejection: the
// customary absolute epsilon depends on the scene's scale, which this project avoids.
// Neighbouring triangles compute their edge tests from different edge vectors, so a ray
// through a shared edge can miss both: the leak the benchmark measures.
inline shared::TriangleHit intersectMollerTrumbore(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1,
                                                   const glm::vec3& p2, bool cullBackFace) {
    shared::TriangleHit h{false, kNoHitT, 0.0f, 0.0f};
    if (shared::triangleHasNoArea(p0, p1, p2)) return h;
    const glm::vec3 e1 = p1 - p0, e2 = p2 - p0;
    const glm::vec3 p = glm::cross(ray.dir, e2);
    const float det = glm::dot(e1, p);
    if (det == 0.0f) return h;
    if (shared::backFaceIsCulled(cullBackFace, det)) return h;  // det = -dot(d, e1 x e2), as the rule wants
    const float inv = 1.0f / det;
    const glm::vec3 s = ray.origin - p0;
    const float u = glm::dot(s, p) * inv;
    if (!(u >= 0.0f && u <= 1.0f)) return h;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(ray.dir, q) * inv;
    if (!(v >= 0.0f && u + v <= 1.0f)) return h;
    const float t = glm::dot(e2, q) * inv;
    if (!std::isfinite(t)) return h;
    h = shared::TriangleHit{true, t, u, v};
    return h;
}

// A float32 ray widened to float64 (exactly), with the watertight test's permutation and
// shear recomputed in float64.
struct RayF64 {
    glm::dvec3 origin;
    glm::dvec3 dir;
    double tmin = 0.0;
    int kx = 0, ky = 1, kz = 2;
    glm::dvec3 shear{0.0};
};

inline RayF64 toF64(const Ray& r) {
    RayF64 d;
    d.origin = glm::dvec3(r.origin);
    d.dir = glm::dvec3(r.dir);
    d.tmin = r.tmin;
    d.kx = int(r.axes & 3u);
    d.ky = int((r.axes >> 2) & 3u);
    d.kz = int((r.axes >> 4) & 3u);
    d.shear = glm::dvec3(d.dir[d.kx] / d.dir[d.kz], d.dir[d.ky] / d.dir[d.kz], 1.0 / d.dir[d.kz]);
    return d;
}

struct TriangleHitF64 {
    bool hit = false;
    double t = 0.0;
    double u = 0.0;
    double v = 0.0;
};

// The watertight test of predicates.glsl in float64. Shared edges still give exactly negated
// edge values (the same products in the other order), so it is watertight too; its rounding
// is about 2^-29 of float32's, far inside the benchmark's near-tie band.
inline TriangleHitF64 intersectWatertightF64(const RayF64& ray, const glm::vec3& p0, const glm::vec3& p1,
                                             const glm::vec3& p2, bool cullBackFace) {
    TriangleHitF64 h;
    const glm::dvec3 a = glm::dvec3(p0) - ray.origin, b = glm::dvec3(p1) - ray.origin, c = glm::dvec3(p2) - ray.origin;
    const double ax = a[ray.kx] - ray.shear.x * a[ray.kz], ay = a[ray.ky] - ray.shear.y * a[ray.kz];
    const double bx = b[ray.kx] - ray.shear.x * b[ray.kz], by = b[ray.ky] - ray.shear.y * b[ray.kz];
    const double cx = c[ray.kx] - ray.shear.x * c[ray.kz], cy = c[ray.ky] - ray.shear.y * c[ray.kz];
    const double eu = cx * by - cy * bx, ev = ax * cy - ay * cx, ew = bx * ay - by * ax;
    if ((eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0)) return h;
    const double det = eu + ev + ew;
    if (det == 0.0) return h;
    // shared::backFaceIsCulled in float64 (rounding a tiny det to float could lose its sign).
    if (cullBackFace && det < 0.0) return h;
    // The float32 test's rules, with float64's slack: no area, or the ray outside the box of
    // the projected vertices (docs/correctness.md).
    const double reach = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z), std::abs(b.x), std::abs(b.y),
                                   std::abs(b.z), std::abs(c.x), std::abs(c.y), std::abs(c.z)});
    const double slack = reach * 0x1p-49;
    if (std::min({ax, bx, cx}) > slack || std::max({ax, bx, cx}) < -slack || std::min({ay, by, cy}) > slack ||
        std::max({ay, by, cy}) < -slack)
        return h;
    if (shared::triangleHasNoArea(p0, p1, p2)) return h;
    const double tScaled = ray.shear.z * (eu * a[ray.kz] + ev * b[ray.kz] + ew * c[ray.kz]);
    if (det > 0.0 ? tScaled <= 0.0 : tScaled >= 0.0) return h;
    h.hit = true;
    h.t = tScaled / det;
    h.u = ev / det;
    h.v = ew / det;
    return h;
}

// Exact-geometry triangle/box overlap by separating axes (Akenine-Moller 2001): the box's
// three axes, the triangle's normal and the nine edge/axis cross products, in float64.
// Conservative: each axis gets a slack of 2^-40 of the magnitudes involved, far above
// float64 rounding, so an overlapping pair is never declared separate.
inline bool triangleOverlapsBoxSat(const Triangle& tri, const Bounds& triBounds, const glm::vec3& lo,
                                   const glm::vec3& hi) {
    if (!shared::boundsOverlap(triBounds.lo, triBounds.hi, lo, hi)) return false;
    const glm::dvec3 centre = 0.5 * (glm::dvec3(lo) + glm::dvec3(hi));
    const glm::dvec3 half = 0.5 * (glm::dvec3(hi) - glm::dvec3(lo));
    const glm::dvec3 v[3] = {glm::dvec3(tri.v0) - centre, glm::dvec3(tri.v1) - centre, glm::dvec3(tri.v2) - centre};
    constexpr double kSlack = 0x1p-40;
    auto separates = [&](const glm::dvec3& axis) {
        const double p0 = glm::dot(axis, v[0]), p1 = glm::dot(axis, v[1]), p2 = glm::dot(axis, v[2]);
        const glm::dvec3 absAxis = glm::abs(axis);
        const double radius = glm::dot(half, absAxis);
        const glm::dvec3 reach = glm::max(glm::max(glm::abs(v[0]), glm::abs(v[1])), glm::abs(v[2]));
        const double slack = kSlack * (glm::dot(absAxis, reach) + radius);
        return std::min({p0, p1, p2}) > radius + slack || std::max({p0, p1, p2}) < -radius - slack;
    };
    const glm::dvec3 edges[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    if (separates(glm::cross(edges[0], edges[1]))) return false;
    for (const glm::dvec3& e : edges)
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 unit(0.0);
            unit[axis] = 1.0;
            if (separates(glm::cross(e, unit))) return false;
        }
    return true;
}

// Our reading of Mora's simplified triangle/box test (thesis section 2.2.4: Akenine-Moller's
// test without its special cases, refined only below 100 triangles): bounds overlap with the
// unwidened cell, plus, in small nodes, the plane/box test in float32 without slack. Without
// the rounding margin it can drop a triangle whose hit the leaf test would still report.
constexpr unsigned kMoraRefineBelow = 100;

inline bool triangleOverlapsBoxMora(const Triangle& tri, const Bounds& triBounds, const glm::vec3& lo,
                                    const glm::vec3& hi, unsigned nodeTriangles) {
    if (!shared::boundsOverlap(triBounds.lo, triBounds.hi, lo, hi)) return false;
    if (nodeTriangles >= kMoraRefineBelow) return true;
    const glm::vec3 centre = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
    const glm::vec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    const float d = glm::dot(n, tri.v0 - centre);
    return std::abs(d) <= glm::dot(half, glm::abs(n));
}

}  // namespace dacrt
