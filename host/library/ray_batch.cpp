// The public RayBatch: a camera's primary rays as `dacrt render` makes them, or the caller's
// rays (origins and directions apart, or six floats per ray) made canonical by makeRay (or,
// with their length as given, by segmentRay), with messages that name the caller's element.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

#include <dacrt/errors.hpp>

#include "core/system_memory.hpp"
#include "cpu/secondary_rays.hpp"
#include "library/api_state.hpp"

namespace dacrt {

namespace {

// As dacrt render's --size.
constexpr int kMaxImageSide = 16384;

std::optional<glm::dvec3> vectorOf(const std::optional<std::array<double, 3>>& v) {
    if (!v) return std::nullopt;
    return glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
}

void checkSegmentSizes(std::size_t rays, std::size_t tmin, std::size_t tmax) {
    for (const auto& [name, size] : {std::pair{"tmin", tmin}, std::pair{"tmax", tmax}})
        if (size != 0 && size != rays)
            throw InputError(std::string(name) + ": " + std::to_string(size) + " values for " + std::to_string(rays) +
                             " rays (one per ray, or none)");
}

void checkRayArraySizes(std::size_t origins, std::size_t directions, std::size_t tmin, std::size_t tmax) {
    if (origins % 3 != 0)
        throw InputError("origins: " + std::to_string(origins) + " floats are not whole points (x, y and z per ray)");
    if (directions != origins)
        throw InputError("directions: " + std::to_string(directions) + " floats for " + std::to_string(origins / 3) +
                         " origins (x, y and z per ray)");
    checkSegmentSizes(origins / 3, tmin, tmax);
}

// The batch's own rays (64 bytes each, then the hits a trace returns) must fit in memory before
// they are made.
void checkBatchFits(std::size_t rays) {
    checkFitsInMemory("a batch of " + std::to_string(rays) + " rays", std::uint64_t(rays) * (sizeof(Ray) + sizeof(Hit)),
                      "trace the rays in smaller batches");
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

std::string text(const glm::vec3& v) {
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return s.str();
}

// The direction traced as given (DirectionLength::AsGiven), in segmentRay's range: its
// largest component from 2^-64 (smaller ones flush to zero) to 2^62.
Ray segmentAt(const glm::vec3& origin, const glm::vec3& direction, float start, float end) {
    const auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    const float largest = std::max({std::abs(direction.x), std::abs(direction.y), std::abs(direction.z)});
    if (!finite(origin) || !finite(direction) || !(largest >= 0x1p-64f && largest <= 0x1p62f))
        throw InputError("ray: origin " + text(origin) + " must be finite, and the direction " + text(direction) +
                         " finite with its largest component within 2^-64 .. 2^62, to be traced as given");
    Ray ray = shared::segmentRay(origin, direction, end);
    ray.tmin = start;
    return ray;
}

// Ray i of the caller's arrays: its origin and direction at `origin` and `direction` (three
// floats each), its segment in tmin and tmax.
Ray rayAt(const float* origin3, const float* direction3, std::span<const float> tmin, std::span<const float> tmax,
          DirectionLength length, std::size_t i) {
    const float start = tmin.empty() ? 0.0f : tmin[i];
    if (!(start >= 0.0f) || !std::isfinite(start))
        throw InputError("tmin[" + std::to_string(i) + "] is " + std::to_string(start) + ": it must be finite and >= 0");
    const glm::vec3 origin(origin3[0], origin3[1], origin3[2]);
    const glm::vec3 direction(direction3[0], direction3[1], direction3[2]);
    try {
        if (length == DirectionLength::AsGiven) return segmentAt(origin, direction, start, segmentEnd(tmax, i, start));
        Ray ray = makeRay(origin, glm::dvec3(direction), start);
        ray.tmax = segmentEnd(tmax, i, start);
        return ray;
    } catch (const InputError& e) {
        // The ray makers' messages name no ray ("ray: origin ..."): here it names the caller's.
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
    checkBatchFits(std::size_t(width) * std::size_t(height));
    const TraceScene::Impl& s = *scene.impl_;
    const CameraOptions options{.eye = vectorOf(camera.eye), .target = vectorOf(camera.target),
                                .up = vectorOf(camera.up), .fovDegrees = camera.fovDegrees};
    const Camera view = makeCameras(s.scene, s.box, options, double(width) / double(height)).front();
    auto impl = std::make_unique<Impl>();
    impl->rays = primaryRays(view, width, height);
    impl->imageWidth = std::uint32_t(width);
    impl->frustum = viewFrustum(view, width, height);
    impl->pinholeRays = impl->frustum.has_value();
    return RayBatch(std::move(impl));
}

RayBatch RayBatch::fromArrays(std::span<const float> origins, std::span<const float> directions,
                              std::span<const float> tmin, std::span<const float> tmax, DirectionLength length) {
    checkRayArraySizes(origins.size(), directions.size(), tmin.size(), tmax.size());
    const std::size_t count = origins.size() / 3;
    checkBatchFits(count);
    auto impl = std::make_unique<Impl>();
    impl->rays.reserve(count);
    for (std::size_t i = 0; i < count; ++i)
        impl->rays.push_back(rayAt(&origins[3 * i], &directions[3 * i], tmin, tmax, length, i));
    return RayBatch(std::move(impl));
}

RayBatch RayBatch::fromRays(std::span<const float> rays, std::span<const float> tmin, std::span<const float> tmax,
                            DirectionLength length) {
    if (rays.size() % 6 != 0)
        throw InputError("rays: " + std::to_string(rays.size()) +
                         " floats are not whole rays (six per ray: origin x, y, z, then direction x, y, z)");
    const std::size_t count = rays.size() / 6;
    checkSegmentSizes(count, tmin.size(), tmax.size());
    checkBatchFits(count);
    auto impl = std::make_unique<Impl>();
    impl->rays.reserve(count);
    for (std::size_t i = 0; i < count; ++i) impl->rays.push_back(rayAt(&rays[6 * i], &rays[6 * i + 3], tmin, tmax, length, i));
    return RayBatch(std::move(impl));
}

std::size_t RayBatch::size() const { return impl_->rays.size(); }

void RayBatch::writeRays(std::span<float> rays) const {
    if (rays.size() != 6 * impl_->rays.size())
        throw InputError("writeRays: " + std::to_string(rays.size()) + " floats for " +
                         std::to_string(impl_->rays.size()) + " rays (six per ray)");
    for (std::size_t i = 0; i < impl_->rays.size(); ++i) {
        const Ray& r = impl_->rays[i];
        const float six[6] = {r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z};
        std::copy(six, six + 6, rays.begin() + std::ptrdiff_t(6 * i));
    }
}

}  // namespace dacrt
