// The public RayBatch: a camera's primary rays as `dacrt render` makes them, or the caller's
// rays made canonical by makeRay, with messages that name the caller's element.
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include <dacrt/errors.hpp>

#include "library/api_state.hpp"

namespace dacrt {

namespace {

// As dacrt render's --size.
constexpr int kMaxImageSide = 16384;

std::optional<glm::dvec3> vectorOf(const std::optional<std::array<double, 3>>& v) {
    if (!v) return std::nullopt;
    return glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
}

void checkRayArraySizes(std::size_t origins, std::size_t directions, std::size_t tmin, std::size_t tmax) {
    if (origins % 3 != 0)
        throw InputError("origins: " + std::to_string(origins) + " floats are not whole points (x, y and z per ray)");
    if (directions != origins)
        throw InputError("directions: " + std::to_string(directions) + " floats for " + std::to_string(origins / 3) +
                         " origins (x, y and z per ray)");
    for (const auto& [name, size] : {std::pair{"tmin", tmin}, std::pair{"tmax", tmax}})
        if (size != 0 && size != origins / 3)
            throw InputError(std::string(name) + ": " + std::to_string(size) + " values for " +
                             std::to_string(origins / 3) + " rays (one per ray, or none)");
}

// The ray's segment end: +infinity stands for an unbounded ray, whose tmax is kNoHitT (no
// infinity enters the arithmetic).
float segmentEnd(std::span<const float> tmax, std::size_t i, float tmin) {
    if (tmax.empty()) return kNoHitT;
    const float end = tmax[i] == std::numeric_limits<float>::infinity() ? kNoHitT : tmax[i];
    if (!(end >= tmin))  // NaN too
        throw InputError("tmax[" + std::to_string(i) + "] is " + std::to_string(tmax[i]) + ", below the ray's tmin " +
                         std::to_string(tmin) + " (a hit needs tmin < t <= tmax)");
    return end;
}

Ray rayAt(std::span<const float> origins, std::span<const float> directions, std::span<const float> tmin,
          std::span<const float> tmax, std::size_t i) {
    const float start = tmin.empty() ? 0.0f : tmin[i];
    if (!(start >= 0.0f) || !std::isfinite(start))
        throw InputError("tmin[" + std::to_string(i) + "] is " + std::to_string(start) + ": it must be finite and >= 0");
    const glm::vec3 origin(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]);
    const glm::dvec3 direction(directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]);
    try {
        Ray ray = makeRay(origin, direction, start);
        ray.tmax = segmentEnd(tmax, i, start);
        return ray;
    } catch (const InputError& e) {
        // makeRay's message names no ray ("ray: origin ..."): here it names the caller's.
        const std::string what = e.what();
        const std::string_view unnamed = "ray: ";
        throw InputError("ray " + std::to_string(i) + ": " + (what.starts_with(unnamed) ? what.substr(unnamed.size()) : what));
    }
}

}  // namespace

RayBatch::RayBatch(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RayBatch::RayBatch(RayBatch&&) noexcept = default;
RayBatch& RayBatch::operator=(RayBatch&&) noexcept = default;
RayBatch::~RayBatch() = default;

RayBatch RayBatch::fromCamera(const TraceScene& scene, const CameraSpec& camera, int width, int height) {
    if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
        throw InputError("camera rays: width and height must lie in 1.." + std::to_string(kMaxImageSide) + " (got " +
                         std::to_string(width) + "x" + std::to_string(height) + ")");
    const TraceScene::Impl& s = *scene.impl_;
    const CameraOptions options{.eye = vectorOf(camera.eye), .target = vectorOf(camera.target),
                                .up = vectorOf(camera.up), .fovDegrees = camera.fovDegrees};
    const Camera view = makeCameras(s.scene, s.box, options, double(width) / double(height)).front();
    auto impl = std::make_unique<Impl>();
    impl->rays = primaryRays(view, width, height);
    impl->imageWidth = std::uint32_t(width);
    impl->frustum = viewFrustum(view, width, height);
    return RayBatch(std::move(impl));
}

RayBatch RayBatch::fromArrays(std::span<const float> origins, std::span<const float> directions,
                              std::span<const float> tmin, std::span<const float> tmax) {
    checkRayArraySizes(origins.size(), directions.size(), tmin.size(), tmax.size());
    auto impl = std::make_unique<Impl>();
    impl->rays.reserve(origins.size() / 3);
    for (std::size_t i = 0; i < origins.size() / 3; ++i) impl->rays.push_back(rayAt(origins, directions, tmin, tmax, i));
    return RayBatch(std::move(impl));
}

std::size_t RayBatch::size() const { return impl_->rays.size(); }

}  // namespace dacrt
