#pragma once
// The render command's scene and camera rays, which it makes itself with core (a glTF document
// posed at each instant, orbit cameras, antialiasing offsets), as the public API's inputs.
#include <cstdint>
#include <optional>
#include <vector>

#include <dacrt/rays.hpp>
#include <dacrt/scene.hpp>

#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

// A copy of a scene checked as the loader checks it, its face rule applied.
TraceScene traceSceneOf(const Scene& scene);

// A camera's primary rays, one per pixel, row-major: imageWidth pixels a row; the frustum
// (a perspective camera's) for the skip of the triangles outside it.
RayBatch cameraRayBatch(const std::vector<Ray>& rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum);

}  // namespace dacrt
