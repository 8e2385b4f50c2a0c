#pragma once
// The render command's scene and camera rays, which it makes itself with core (a glTF document
// posed at each instant, orbit cameras, antialiasing offsets), handed to the public API without
// a copy: render keeps reading them (shading, stats) through the API's objects.
#include <cstdint>
#include <optional>
#include <vector>

#include <dacrt/rays.hpp>
#include <dacrt/scene.hpp>

#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

// The scene, checked as the loader checks it and its face rule applied, moved into a
// TraceScene; box: its triangles' (sceneBounds).
TraceScene adoptScene(Scene scene, const Box& box);
const Scene& sceneOf(const TraceScene& scene);
const Box& boxOf(const TraceScene& scene);

// A camera's primary rays, one per pixel, row-major: imageWidth pixels a row; the frustum
// (a perspective camera's) for the skip of the triangles outside it.
RayBatch adoptCameraRays(std::vector<Ray> rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum);
const std::vector<Ray>& raysOf(const RayBatch& rays);

}  // namespace dacrt
