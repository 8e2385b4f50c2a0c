#include "oracle/error_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "oracle/compare.hpp"
#include "core/errors.hpp"

namespace dacrt {
namespace {

struct SegmentPoint {
    double distance;
    double s;  // 0 at the segment's start, 1 at its end
};

SegmentPoint closestOnSegment(const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double s = len2 > 0.0 ? std::clamp(-glm::dot(a, ab) / len2, 0.0, 1.0) : 0.0;
    return {glm::length(a + s * ab), s};
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

}  // namespace

void ErrorMetrics::add(const ErrorMetrics& o) {
    pixels += o.pixels;
    differingPrim += o.differingPrim;
    nearTies += o.nearTies;
    realErrors += o.realErrors;
    leaks += o.leaks;
    realLeaks += o.realLeaks;
    spuriousHits += o.spuriousHits;
    bothHit += o.bothHit;
    maxRelDepth = std::max(maxRelDepth, o.maxRelDepth);
    sumSqRelDepth += o.sumSqRelDepth;
    sumSqShaded += o.sumSqShaded;
    shadedSamples += o.shadedSamples;
}

double ErrorMetrics::rmsRelDepth() const { return bothHit ? std::sqrt(sumSqRelDepth / double(bothHit)) : 0.0; }

double ErrorMetrics::psnr() const {
    if (sumSqShaded == 0.0 || shadedSamples == 0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(255.0 * 255.0 / (sumSqShaded / double(shadedSamples)));
}

namespace {

// Why a differing pixel is or is not a near tie.
struct RayTriangleProximity {
    double distance = 0.0;          // from the ray's line to the triangle, perpendicular to the ray
    double boundaryDistance = 0.0;  // from the ray's line to the triangle's edges
    double t = 0.0;                 // ray parameter of the triangle's point closest to the line
};

struct ProximityDetail {
    RayTriangleProximity p;
    glm::dvec3 towardsBoundary{0.0};  // from the ray's line to the triangle's nearest boundary point
};

ProximityDetail proximityDetail(const Ray& ray, const Triangle& tri) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(ray.dir));
    // An orthonormal frame with d: the plane it spans with u, w is perpendicular to the ray.
    const glm::dvec3 helper = std::abs(d.x) < 0.5 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(d, helper)), w = glm::cross(d, u);
    glm::dvec2 p[3];
    double along[3];
    const glm::vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
    for (int i = 0; i < 3; ++i) {
        const glm::dvec3 q = glm::dvec3(*v[i]) - glm::dvec3(ray.origin);
        p[i] = {glm::dot(q, u), glm::dot(q, w)};
        along[i] = glm::dot(q, d) / glm::length(glm::dvec3(ray.dir));
    }
    ProximityDetail out;
    RayTriangleProximity& r = out.p;
    r.boundaryDistance = std::numeric_limits<double>::infinity();
    double bary[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        const SegmentPoint sp = closestOnSegment(p[i], p[(i + 1) % 3]);
        if (sp.distance < r.boundaryDistance) {
            r.boundaryDistance = sp.distance;
            bary[0] = bary[1] = bary[2] = 0.0;
            bary[i] = 1.0 - sp.s;
            bary[(i + 1) % 3] = sp.s;
            const glm::dvec2 c = p[i] + sp.s * (p[(i + 1) % 3] - p[i]);
            out.towardsBoundary = c.x * u + c.y * w;
        }
    }
    r.distance = r.boundaryDistance;
    // The line's own point in the projection is the origin (0, 0).
    const double area = cross2(p[1] - p[0], p[2] - p[0]);
    const double e0 = cross2(p[1], p[2]), e1 = cross2(p[2], p[0]), e2 = cross2(p[0], p[1]);
    if (area != 0.0 && ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))) {
        r.distance = 0.0;
        bary[0] = e0 / area;
        bary[1] = e1 / area;
        bary[2] = e2 / area;
    }
    r.t = bary[0] * along[0] + bary[1] * along[1] + bary[2] * along[2];
    return out;
}

// A leak next to an edge is a near tie only where the surface ends there: at a silhouette
// (the neighbour folds back behind the edge) or a hole's rim. The surface continues when the
// ray moved 2 tolerances outward across the nearest boundary point of the reference's
// triangle still hits another triangle at about the same depth; a watertight test can never
// let a ray through between two such triangles, whatever its rounding.
bool surfaceContinues(const Ray& ray, const ProximityDetail& near, const std::vector<Triangle>& triangles,
                      const std::vector<Bounds>& bounds, std::uint32_t refPrim, double refT, double tol) {
    const double reach = glm::length(near.towardsBoundary);
    if (reach == 0.0) return false;  // degenerate: the ray runs along the edge itself
    Ray moved = ray;
    moved.origin = glm::vec3(glm::dvec3(ray.origin) + near.towardsBoundary * ((reach + 2.0 * tol) / reach));
    const glm::dvec3 hitPoint = glm::dvec3(ray.origin) + refT * glm::dvec3(ray.dir);
    const double depthBound = 4.0 * tol + 1e-3 * refT;
    for (std::uint32_t q = 0; q < triangles.size(); ++q) {
        if (q == refPrim) continue;
        const Bounds& b = bounds[q];
        bool close = true;
        for (int a = 0; a < 3; ++a)
            close = close && hitPoint[a] >= double(b.lo[a]) - depthBound - 4 * tol &&
                    hitPoint[a] <= double(b.hi[a]) + depthBound + 4 * tol;
        if (!close) continue;
        const RayTriangleProximity other = proximityDetail(moved, triangles[q]).p;
        if (other.distance <= 0.5 * tol && std::abs(other.t - refT) <= depthBound) return true;
    }
    return false;
}

}  // namespace

ErrorMetrics measureErrors(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                           const std::vector<Ray>& rays, const std::vector<ReferenceHit>& reference,
                           const std::vector<Hit>& hits, const std::vector<std::uint8_t>& shadedReference,
                           const std::vector<std::uint8_t>& shadedBackend, ThreadPool& pool) {
    if (reference.size() != rays.size() || hits.size() != rays.size() || shadedReference.size() != 3 * rays.size() ||
        shadedBackend.size() != 3 * rays.size())
        throw std::logic_error("measureErrors: the images do not match the rays");
    double magnitude = 0.0;
    for (const Bounds& b : bounds)
        for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::abs(double(b.lo[a])), std::abs(double(b.hi[a]))});
    if (!rays.empty())
        for (int a = 0; a < 3; ++a) magnitude = std::max(magnitude, std::abs(double(rays[0].origin[a])));

    const std::size_t chunks = std::min<std::size_t>(rays.size(), 64);
    std::vector<ErrorMetrics> parts(chunks);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        ErrorMetrics& m = parts[c];
        const std::size_t begin = rays.size() * c / chunks, end = rays.size() * (c + 1) / chunks;
        for (std::size_t i = begin; i < end; ++i) {
            ++m.pixels;
            for (int k = 0; k < 3; ++k) {
                const double diff = double(shadedReference[3 * i + k]) - double(shadedBackend[3 * i + k]);
                m.sumSqShaded += diff * diff;
            }
            m.shadedSamples += 3;
            const ReferenceHit& ref = reference[i];
            const Hit& got = hits[i];
            const bool refHit = ref.prim != kMissPrim, gotHit = got.prim != kMissPrim;
            if (refHit && gotHit) {
                const double rel = std::abs(double(got.t) - ref.t) / ref.t;
                ++m.bothHit;
                m.maxRelDepth = std::max(m.maxRelDepth, rel);
                m.sumSqRelDepth += rel * rel;
            }
            if (ref.prim == got.prim) continue;
            ++m.differingPrim;
            const Ray& ray = rays[i];
            const double tol = kNearTieRelativeDepth * std::max(refHit ? ref.t : double(got.t), magnitude);
            bool nearTie = false;  // a backend primitive that does not exist stays a real error, not a crash
            if (gotHit && !refHit) ++m.spuriousHits;
            if (gotHit && got.prim < triangles.size()) {
                const RayTriangleProximity p = proximityDetail(ray, triangles[got.prim]).p;
                nearTie = p.distance <= tol && (refHit ? std::abs(p.t - ref.t) <= tol : p.t > -tol);
            } else if (!gotHit) {
                ++m.leaks;
                const ProximityDetail near = proximityDetail(ray, triangles[ref.prim]);
                nearTie = near.p.boundaryDistance <= tol && !surfaceContinues(ray, near, triangles, bounds, ref.prim, ref.t, tol);
                if (!nearTie) ++m.realLeaks;
            }
            if (nearTie)
                ++m.nearTies;
            else
                ++m.realErrors;
        }
    });
    ErrorMetrics total;
    for (const ErrorMetrics& m : parts) total.add(m);
    return total;
}

}  // namespace dacrt
