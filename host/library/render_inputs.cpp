#include "library/render_inputs.hpp"

#include <algorithm>

#include <dacrt/errors.hpp>

#include "library/api_state.hpp"

namespace dacrt {

TraceScene adoptScene(Scene scene, const Box& box) {
    return TraceScene::Impl::wrap(std::make_unique<TraceScene::Impl>(std::move(scene), box));
}

const Scene& sceneOf(const TraceScene& scene) { return TraceScene::Impl::of(scene).scene; }

const Box& boxOf(const TraceScene& scene) { return TraceScene::Impl::of(scene).box; }

void replaceScene(TraceScene& scene, Scene posed) {
    TraceScene::Impl& s = TraceScene::Impl::of(scene);
    if (!s.indices.empty()) throw InternalError("replaceScene: a scene from arrays moves by setPositions");
    if (posed.triangles.size() != s.scene.triangles.size())
        throw InternalError("replaceScene: " + std::to_string(posed.triangles.size()) + " triangles for a scene of " +
                            std::to_string(s.scene.triangles.size()) + " (a new count needs a new scene)");
    std::vector<Triangle> kept = std::move(s.scene.triangles);
    std::copy(posed.triangles.begin(), posed.triangles.end(), kept.begin());
    posed.triangles = std::move(kept);  // a moved vector keeps its memory
    s.scene = std::move(posed);
    touchTriangles(s.scene);
    s.box = sceneBounds(s.scene.triangles);
}

RayBatch adoptCameraRays(std::vector<Ray> rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum) {
    auto impl = std::make_unique<RayBatch::Impl>();
    impl->rays = std::move(rays);
    impl->imageWidth = imageWidth;
    impl->frustum = frustum;
    impl->pinholeRays = frustum.has_value();
    return RayBatch::Impl::wrap(std::move(impl));
}

const std::vector<Ray>& raysOf(const RayBatch& rays) { return RayBatch::Impl::of(rays).rays; }

std::vector<Ray> releaseRays(RayBatch rays) { return std::move(RayBatch::Impl::of(rays).rays); }

}  // namespace dacrt
