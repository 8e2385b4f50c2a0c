#include "library/render_inputs.hpp"

#include "library/api_state.hpp"

namespace dacrt {

TraceScene adoptScene(Scene scene, const Box& box) {
    return TraceScene::Impl::wrap(std::make_unique<TraceScene::Impl>(std::move(scene), box));
}

const Scene& sceneOf(const TraceScene& scene) { return TraceScene::Impl::of(scene).scene; }

const Box& boxOf(const TraceScene& scene) { return TraceScene::Impl::of(scene).box; }

RayBatch adoptCameraRays(std::vector<Ray> rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum) {
    auto impl = std::make_unique<RayBatch::Impl>();
    impl->rays = std::move(rays);
    impl->imageWidth = imageWidth;
    impl->frustum = frustum;
    return RayBatch::Impl::wrap(std::move(impl));
}

const std::vector<Ray>& raysOf(const RayBatch& rays) { return RayBatch::Impl::of(rays).rays; }

}  // namespace dacrt
