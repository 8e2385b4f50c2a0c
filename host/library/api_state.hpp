#pragma once
// The library's side of the public TraceScene and RayBatch (include/dacrt/): the arrays every
// backend reads, prepared once.
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <dacrt/rays.hpp>
#include <dacrt/scene.hpp>

#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

struct TraceScene::Impl {
    Scene scene;  // checked (validateScene), its face rule applied
    // The triangles' box, for cameras framing the scene and the peers; dacrt's backends compute
    // the triangles' bounds and the box anew at each trace, as every frame of a dynamic scene
    // must (Tracer::Impl::frameBounds).
    Box box;
    // fromArrays where triangles with no area were dropped: the caller's number of each traced
    // triangle. Empty: the traced triangles' indices are the ids.
    std::vector<std::uint32_t> callerIds;
    // fromArrays: the caller's indices and vertex count, from which setPositions gathers the
    // triangles anew. Empty: a scene from a file (or the library's own), with no vertices to move.
    std::vector<std::uint32_t> indices;
    std::size_t vertices = 0;
    // Unique in the process: the peers keep their structure over this scene's triangles, whose
    // array keeps its address and size while the scene lives (FrameGeometry::sceneId).
    const std::uint64_t id = newId();

    explicit Impl(Scene checked)
        : scene(std::move(checked)), box(sceneBounds(scene.triangles)) {}
    Impl(Scene checked, const Box& sceneBox) : scene(std::move(checked)), box(sceneBox) {}

    static std::uint64_t newId();

    // The public scene around a prepared one (the library's own inputs, render_inputs.hpp).
    static TraceScene wrap(std::unique_ptr<Impl> impl) { return TraceScene(std::move(impl)); }
    static const Impl& of(const TraceScene& scene) { return *scene.impl_; }
    static Impl& of(TraceScene& scene) { return *scene.impl_; }
};

struct RayBatch::Impl {
    std::vector<Ray> rays;
    std::uint32_t imageWidth = 0;        // a camera's: its pixels in a row (0: not an image)
    std::optional<ViewFrustum> frustum;  // a perspective camera's
    // A perspective camera's rays (PixelRays): the eye for every origin, tmin 0 and tmax
    // unbounded, bit for bit, by construction; the trace then scans them for none of it
    // (FrameGeometry::uniformByConstruction). The batch is immutable, so it stays true.
    bool pinholeRays = false;

    static RayBatch wrap(std::unique_ptr<Impl> impl) { return RayBatch(std::move(impl)); }
    static const Impl& of(const RayBatch& rays) { return *rays.impl_; }
    static Impl& of(RayBatch& rays) { return *rays.impl_; }
};

}  // namespace dacrt
