#pragma once
// Everything a tracer reads, prepared once per frame and shared by every backend.
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

struct FrameGeometry {
    const std::vector<Triangle>* triangles = nullptr;
    const std::vector<Bounds>* triangleBounds = nullptr;
    const std::vector<Ray>* rays = nullptr;
    Box sceneBox;          // exact bounds of the triangles
    glm::vec3 rayOrigin{};  // the first ray's origin: every ray's when raysShareStart
    // Per axis, the largest |origin| over the rays (the filter margin's input).
    glm::vec3 farthestOrigin{};
    // A point on the side every ray comes from, per axis: the shared origin, or -FLT_MAX
    // (+FLT_MAX) on an axis along which no ray travels towards - (+). The child of a split on
    // this point's side is the one every crossing ray meets first (nearSideKnown), which is
    // what lets a hit inside the first child end the ray. Rays of many origins travelling
    // both ways along an axis have no such point.
    glm::vec3 nearSide{};
    bool nearSideKnown = false;
    float margin = 0.0f;    // filter widening, see filterMargin()
    bool raysShareStart = false;  // see raysShareStart()
    std::uint32_t imageWidth = 0;  // rays are an image's pixels, row by row, this many a row (0: unknown)
    // Primary rays of one camera: the pyramid they lie in (the view-frustum skip needs it).
    std::optional<ViewFrustum> frustum;
    // The triangles a ray can hit, ascending, when a skip dropped others (triangle_skips.hpp);
    // null: every triangle. Ids keep indexing `triangles`.
    const std::vector<std::uint32_t>* tracedTriangles = nullptr;
    // Nonzero: frames with the same value have the same triangles and bounds, bit for bit (the
    // gpu keeps them on the device: gpu/resident_triangles.hpp). 0: unknown.
    std::uint64_t trianglesVersion = 0;

    std::size_t tracedTriangleCount() const { return tracedTriangles ? tracedTriangles->size() : triangles->size(); }
    std::uint32_t tracedTriangle(std::size_t i) const { return tracedTriangles ? (*tracedTriangles)[i] : std::uint32_t(i); }
};

// Whether every ray has the first ray's origin and tmin, bit for bit (primary rays do): the
// kernels (SIMD filters, compute shaders) then take them once instead of loading them per
// ray, with the per-ray arithmetic unchanged.
bool raysShareStart(const std::vector<Ray>& rays);

// Widening applied to every box before a ray or triangle filter, so that rounding in the
// intersection test can never move a hit out of the cells that test it. See
// docs/correctness.md for the derivation: 64 units in the last place of the largest
// coordinate magnitude among the scene bounds and the ray origins (farthestOrigin: per axis,
// the largest |origin|).
float filterMargin(const Box& sceneBox, const glm::vec3& farthestOrigin);

// Throws InputError naming `tracer` when the rays have no near side (nearSideKnown): the DACRT
// tracers need one until rays are classified by direction per ray.
void requireNearSide(const FrameGeometry& g, const char* tracer);

// The frame every tracer reads: the arrays (which must outlive it), the scene box, the rays'
// origins and near side, and the filter margin derived from them.
// imageWidth: the rays' row length when they are an image's pixels (packets group them in
// tiles), else 0.
FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox, std::uint32_t imageWidth = 0);

}  // namespace dacrt
