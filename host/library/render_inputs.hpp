#pragma once
// The scene and camera rays the render and bench commands make themselves with core (a glTF
// document posed at each instant, orbit cameras, antialiasing offsets), handed to the public API
// without a copy: the commands keep reading them (shading, stats, checks) through the API's
// objects.
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

// A scene made by adoptScene becomes `posed`, the same scene at another instant of its
// animation, with as many triangles (InternalError otherwise): its triangles are copied into
// the scene's own array, which keeps its address, so that a Tracer follows them as a dynamic
// scene's next frame (the peers refit or rebuild the structure they keep over that array; the
// gpu uploads them again: a new trianglesVersion). The box is its triangles'.
void replaceScene(TraceScene& scene, Scene posed);

// A camera's primary rays (primaryRays'), one per pixel, row-major: imageWidth pixels a row;
// the frustum (a perspective camera's) for the skip of the triangles outside it. With a
// frustum the rays are taken as PixelRays makes a perspective camera's: one origin, tmin and
// tmax (RayBatch::Impl::pinholeRays).
RayBatch adoptCameraRays(std::vector<Ray> rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum);
const std::vector<Ray>& raysOf(const RayBatch& rays);
// The rays moved out of the batch, for their memory to hold the next frame's.
std::vector<Ray> releaseRays(RayBatch rays);

}  // namespace dacrt
