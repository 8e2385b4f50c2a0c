#include "library/render_inputs.hpp"

#include "library/api_state.hpp"

namespace dacrt {

TraceScene traceSceneOf(const Scene& scene) { return TraceScene::Impl::wrap(std::make_unique<TraceScene::Impl>(scene)); }

RayBatch cameraRayBatch(const std::vector<Ray>& rays, std::uint32_t imageWidth, std::optional<ViewFrustum> frustum) {
    auto impl = std::make_unique<RayBatch::Impl>();
    impl->rays = rays;
    impl->imageWidth = imageWidth;
    impl->frustum = frustum;
    return RayBatch::Impl::wrap(std::move(impl));
}

}  // namespace dacrt
