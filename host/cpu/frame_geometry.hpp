#pragma once
// Everything a tracer reads, prepared once per frame and shared by every backend.
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "cpu/triangle_faces.hpp"

namespace dacrt {

// Which child of a split each ray meets first: what lets a hit inside the first child end the
// ray (docs/correctness.md, "Front to back").
enum class ChildOrder {
    // The child on nearSide's side, for every ray: rays that share an origin (nearSide), or
    // whose direction signs agree per axis (nearSide at -FLT_MAX or +FLT_MAX per axis).
    NearSide,
    // Rays of many origins travelling both ways: each split classifies its live rays by the
    // sign of their direction along its axis, and the low child is visited by the rays moving
    // up, then the high child by all, then the low child again by the rays moving down. For
    // any hit, where the order changes no result, every ray visits the low child, then the high.
    PerRay,
};

// What a tracer returns for each ray: the closest hit (primary rays), or any hit in the ray's
// segment (shadow and occlusion rays: the visibility bit is exact, the hit itself may be any
// of those in the segment).
enum class HitQuery { Closest, Any };

struct FrameGeometry {
    const std::vector<Triangle>* triangles = nullptr;
    const std::vector<Bounds>* triangleBounds = nullptr;
    // triangleBounds' coordinates in six columns (triangleBoundsInParallel's columns), which the
    // triangle filters then read instead of the records (simd::TriangleFaces); null: none.
    const std::vector<float>* boundsColumns = nullptr;
    const std::vector<Ray>* rays = nullptr;
    Box sceneBox;          // exact bounds of the triangles
    glm::vec3 rayOrigin{};  // the first ray's origin: every ray's when raysShareStart
    // Per axis, the largest |origin| over the rays (the filter margin's input).
    glm::vec3 farthestOrigin{};
    // ChildOrder::NearSide: a point on the side every ray comes from, per axis: the shared
    // origin, or -FLT_MAX (+FLT_MAX) on an axis along which no ray travels towards - (+).
    glm::vec3 nearSide{};
    ChildOrder order = ChildOrder::NearSide;
    HitQuery query = HitQuery::Closest;
    float margin = 0.0f;    // filter widening, see filterMargin()
    bool raysShareStart = false;  // see raysShareStart()
    // Every ray has the first one's origin, tmin and tmax, bit for bit, by the way they were
    // made (a pinhole camera's: RayBatch::Impl::pinholeRays): raysShareStart is set without a
    // scan, and the hits' start fills every ray's missHit without reading the rays.
    bool uniformByConstruction = false;
    std::uint32_t imageWidth = 0;  // rays are an image's pixels, row by row, this many a row (0: unknown)
    // Primary rays of one camera: the pyramid they lie in (the view-frustum skip needs it).
    std::optional<ViewFrustum> frustum;
    // The triangles a ray can hit, ascending, when a skip dropped others (triangle_skips.hpp);
    // null: every triangle. Ids keep indexing `triangles`.
    const std::vector<std::uint32_t>* tracedTriangles = nullptr;
    // Nonzero: frames with the same value have the same triangles and bounds, bit for bit (the
    // gpu keeps them on the device: gpu/resident_triangles.hpp). 0: unknown.
    std::uint64_t trianglesVersion = 0;
    // Nonzero: the caller's scene whose `triangles` array this is, unique in the process and
    // kept while the array keeps its address and size: the peers keep their structure over it
    // from frame to frame (library/peer_scenes.hpp). 0: a structure for this frame alone.
    std::uint64_t sceneId = 0;

    // What the triangle filters read: the columns only where they are triangleBounds' (six
    // columns of its length; a frame of a subset of the triangles keeps none).
    simd::TriangleFaces triangleFaces() const {
        if (boundsColumns && boundsColumns->size() != 6 * triangleBounds->size())
            throw InternalError("a frame's bound columns hold " + std::to_string(boundsColumns->size()) +
                                " coordinates for " + std::to_string(triangleBounds->size()) + " triangles");
        return {triangleBounds->data(), boundsColumns ? boundsColumns->data() : nullptr, triangleBounds->size()};
    }
    std::size_t tracedTriangleCount() const { return tracedTriangles ? tracedTriangles->size() : triangles->size(); }
    std::uint32_t tracedTriangle(std::size_t i) const { return tracedTriangles ? (*tracedTriangles)[i] : std::uint32_t(i); }
};

// Whether every ray has the first ray's origin and tmin, bit for bit (primary rays do): the
// kernels (SIMD filters, compute shaders) then take them once instead of loading them per
// ray, with the per-ray arithmetic unchanged.
// pool: the chunks of the scan side by side (none: on the calling thread).
bool raysShareStart(const std::vector<Ray>& rays, ThreadPool* pool = nullptr);
// Whether ray a has b's tmin and tmax, bit for bit (inline: startHits asks it of every ray).
inline bool sameSegment(const Ray& a, const Ray& b) {
    return std::memcmp(&a.tmin, &b.tmin, sizeof(a.tmin)) == 0 && std::memcmp(&a.tmax, &b.tmax, sizeof(a.tmax)) == 0;
}
// Whether every ray has the first one's tmin and tmax, bit for bit (false without rays).
bool raysShareSegment(const std::vector<Ray>& rays);

// ids = the traced triangles' ids in order (g.tracedTriangle(i)), for a traversal to permute;
// in chunks side by side on the pool (none: on the calling thread).
void fillTracedTriangleIds(const FrameGeometry& g, std::vector<std::uint32_t>& ids, ThreadPool* pool = nullptr);

// Widening applied to every box before a ray or triangle filter, so that rounding in the
// intersection test can never move a hit out of the cells that test it. See
// docs/correctness.md for the derivation: 64 units in the last place of the largest
// coordinate magnitude among the scene bounds and the ray origins (farthestOrigin: per axis,
// the largest |origin|).
float filterMargin(const Box& sceneBox, const glm::vec3& farthestOrigin);

// The frame every tracer reads: the arrays (which must outlive it), the scene box, the rays'
// origins and child order (NearSide where one exists, else PerRay), and the filter margin
// derived from them.
// imageWidth: the rays' row length when they are an image's pixels (packets group them in
// tiles), else 0. pool: the passes over the rays in chunks side by side (none: on the
// calling thread). uniformRays: the caller made the rays with one origin, tmin and tmax
// (FrameGeometry::uniformByConstruction); nothing checks it.
FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox, std::uint32_t imageWidth = 0,
                            ThreadPool* pool = nullptr, bool uniformRays = false);

}  // namespace dacrt
