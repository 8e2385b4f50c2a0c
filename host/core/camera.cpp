#include "core/camera.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"

namespace dacrt {
namespace {

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string str(const glm::dvec3& v) {
    std::ostringstream s;
    s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return s.str();
}

Camera lookAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& upHint, double yfov) {
    if (!finite(eye) || !finite(target) || !finite(upHint))
        throw InputError("camera: eye, target and up must be finite, got eye " + str(eye) + ", target " +
                         str(target) + ", up " + str(upHint));
    for (double c : {eye.x, eye.y, eye.z})
        if (std::abs(c) > kMaxCoordinate)
            throw InputError("camera: eye " + str(eye) + " lies outside +-1e9, the coordinate limit");
    const glm::dvec3 f = target - eye;
    if (glm::length(f) == 0.0) throw InputError("camera: eye and target coincide at " + str(eye));
    Camera c;
    c.eye = eye;
    c.forward = glm::normalize(f);
    const glm::dvec3 right = glm::cross(c.forward, upHint);
    if (!(glm::length(right) > 1e-9 * glm::length(upHint)))
        throw InputError("camera: up " + str(upHint) + " is parallel to the view direction " + str(c.forward));
    c.up = glm::normalize(glm::cross(glm::normalize(right), c.forward));
    c.yfovRadians = yfov;
    return c;
}

// How far along z the default front view backs off from the scene's centre: `wanted` (the
// scene's bounding sphere fits the view), within the coordinate limit the eye must keep too. A
// scene within the limit but larger than the view from there is seen from the limit, in part,
// rather than refused; behind it (a negative distance) where the other side has more room.
double frontViewDistance(double centreZ, double wanted) {
    if (centreZ + wanted <= kMaxCoordinate) return wanted;
    const double front = kMaxCoordinate - centreZ, back = kMaxCoordinate + centreZ;
    return front >= back ? front : -std::min(wanted, back);
}

}  // namespace

std::vector<Camera> makeCameras(const Scene& scene, const Box& bounds, const CameraOptions& options, double aspect) {
    const glm::dvec3 centre = glm::dvec3(bounds.center());
    double yfov = glm::radians(kDefaultFovDegrees);
    glm::dvec3 eye, target = centre, up{0.0, 1.0, 0.0};
    const bool fromScene = scene.camera && !options.eye && !options.target;
    if (fromScene) {
        yfov = scene.camera->yfovRadians;
        eye = scene.camera->eye;
        target = eye + scene.camera->forward;
        up = scene.camera->up;
    } else {
        if (options.fovDegrees) yfov = glm::radians(*options.fovDegrees);
        // Front view: back off along +z until the bounding sphere fits the narrower field of view.
        const double radius = 0.5 * glm::length(glm::dvec3(bounds.extent()));
        const double halfFov = 0.5 * std::min(yfov, 2.0 * std::atan(std::tan(0.5 * yfov) * aspect));
        const double distance = std::max(radius, 1e-6) / std::sin(halfFov) * 1.02;
        eye = centre + glm::dvec3(0.0, 0.0, frontViewDistance(centre.z, distance));
    }
    if (options.eye) eye = *options.eye;
    if (options.target) target = *options.target;
    if (options.up) up = *options.up;
    if (options.fovDegrees) {
        const double deg = *options.fovDegrees;
        if (!(deg > 0.0 && deg < 180.0))
            throw InputError("camera: the vertical field of view must lie strictly between 0 and 180 degrees, got " + std::to_string(deg));
        yfov = glm::radians(deg);
    }
    Camera base;
    try {
        base = lookAt(eye, target, up, yfov);
    } catch (const InputError& e) {  // the file's camera, or the view framing its scene: named
        if (scene.name.empty()) throw;
        const std::string source = options.eye || options.target ? "--eye and --target"
                                   : fromScene ? "camera " + std::to_string(scene.camera->cameraIndex) + " of node " +
                                                     std::to_string(scene.camera->node)
                                               : "the front view framing the scene";
        throw InputError(scene.name + ": " + e.what() + " (" + source + ")");
    }
    if (fromScene && scene.camera->projection == Projection::Orthographic) {
        if (options.fovDegrees)
            throw InputError("camera: the scene's camera is orthographic, which has no field of view (--fov); give --eye or --target for a perspective view");
        base.projection = Projection::Orthographic;
        base.ymag = scene.camera->ymag;
        base.yfovRadians = 0.0;
    }
    if (options.orbit < 0) throw InputError("camera: an orbit needs a positive number of cameras");
    if (options.orbit <= 1) return {base};

    std::vector<Camera> cameras;
    for (int k = 0; k < options.orbit; ++k) {
        const double angle = 2.0 * M_PI * double(k) / double(options.orbit);
        const double c = std::cos(angle), s = std::sin(angle);
        auto rotate = [&](const glm::dvec3& v) { return glm::dvec3(c * v.x + s * v.z, v.y, -s * v.x + c * v.z); };
        Camera cam = base;
        cam.eye = centre + rotate(base.eye - centre);
        cam.forward = rotate(base.forward);
        cam.up = rotate(base.up);
        cameras.push_back(cam);
    }
    return cameras;
}

std::optional<ViewFrustum> viewFrustum(const Camera& camera, int width, int height) {
    if (camera.projection == Projection::Orthographic) return std::nullopt;
    // PixelRays' directions are forward + sx right + sy up with |sx| <= x and |sy| <= y;
    // n . d is affine in (sx, sy), so the rectangle's edges bound it.
    const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
    const double y = std::tan(0.5 * camera.yfovRadians), x = y * double(width) / double(height);
    ViewFrustum f;
    f.apex = glm::dvec3(glm::vec3(camera.eye));
    f.inward = {glm::normalize(x * camera.forward + right), glm::normalize(x * camera.forward - right),
                glm::normalize(y * camera.forward + camera.up), glm::normalize(y * camera.forward - camera.up)};
    f.forward = camera.forward;
    f.up = camera.up;
    f.halfHeight = y;
    f.rows = height;
    return f;
}

ViewFrustum rowsFrustum(const ViewFrustum& frustum, int firstRow, int endRow) {
    // PixelRays' rows span sy = (1 - 2 (row + offset) / rows) halfHeight, offset in [0, 1]: from
    // `top` at firstRow's upper edge down to `bottom` at the last row's lower edge. n . d is
    // affine in sy, so those edges bound it, as viewFrustum's do.
    const double top = (1.0 - 2.0 * firstRow / frustum.rows) * frustum.halfHeight;
    const double bottom = (1.0 - 2.0 * endRow / frustum.rows) * frustum.halfHeight;
    ViewFrustum f = frustum;
    f.inward[2] = glm::normalize(frustum.up - bottom * frustum.forward);
    f.inward[3] = glm::normalize(top * frustum.forward - frustum.up);
    return f;
}

namespace {

// makeRay's checks and direction: normalized in double, rounded to float, components below
// 2^-64 flushed to zero (so 1/dir <= 2^64).
glm::vec3 checkedUnitDirection(const glm::vec3& origin, const glm::dvec3& direction) {
    if (!finite(glm::dvec3(origin)) || !finite(direction) || direction == glm::dvec3(0.0))
        throw InputError("ray: origin " + str(glm::dvec3(origin)) + " and direction " + str(direction) +
                         " must be finite and the direction non-zero");
    // glm::normalize's arithmetic, v (1 / sqrt(v . v)), whose squares overflow beyond about
    // 2^511 (a zero direction would follow) and lose bits below about 2^-511: such a direction is
    // first scaled by a power of two (exactly), which gives the result of unbounded exponents.
    // pixel_ray_rows.cpp leaves the same directions to this function.
    glm::dvec3 v = direction;
    double squared = glm::dot(v, v);
    if (!(squared >= std::numeric_limits<double>::min() && squared <= std::numeric_limits<double>::max())) {
        const int exponent = std::ilogb(std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}));
        v = glm::dvec3(std::ldexp(v.x, -exponent), std::ldexp(v.y, -exponent), std::ldexp(v.z, -exponent));
        squared = glm::dot(v, v);
    }
    glm::vec3 d = glm::vec3(v * (1.0 / std::sqrt(squared)));
    for (int a = 0; a < 3; ++a)
        if (std::abs(d[a]) < 0x1p-64f) d[a] = 0.0f;  // keeps every slab bound finite (predicates.glsl)
    return d;
}

}  // namespace

Ray makeRay(const glm::vec3& origin, const glm::dvec3& direction, float tmin) {
    const glm::vec3 d = checkedUnitDirection(origin, direction);
    Ray r{};
    r.origin = origin;
    r.tmin = tmin;
    r.tmax = kNoHitT;
    r.dir = d;
    for (int a = 0; a < 3; ++a) r.invDir[a] = d[a] == 0.0f ? 0.0f : 1.0f / d[a];
    int kz = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(d[a]) > std::abs(d[kz])) kz = a;
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (d[kz] < 0.0f) std::swap(kx, ky);  // keeps the winding, so the sign of det is the facing
    r.axes = std::uint32_t(kx) | std::uint32_t(ky) << 2 | std::uint32_t(kz) << 4;
    r.shear = glm::vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0f / d[kz]);
    return r;
}

PixelRays::PixelRays(const Camera& camera, int width, int height, glm::dvec2 offset)
    : camera_(camera),
      width_(width),
      height_(height),
      offset_(offset),
      right_(glm::normalize(glm::cross(camera.forward, camera.up))),
      aspect_(double(width) / double(height)),
      halfHeight_(camera.projection == Projection::Orthographic ? camera.ymag : std::tan(0.5 * camera.yfovRadians)),
      orthographic_(camera.projection == Projection::Orthographic),
      origin_(glm::vec3(camera.eye)),
      simd_(simdPixels()) {}

std::pair<glm::vec3, glm::dvec3> PixelRays::unrounded(int x, int y) const {
    const double sx = (2.0 * (x + offset_.x) / width_ - 1.0) * halfHeight_ * aspect_;
    const double sy = (1.0 - 2.0 * (y + offset_.y) / height_) * halfHeight_;
    const glm::dvec3 offPlane = sx * right_ + sy * camera_.up;
    if (orthographic_) return {glm::vec3(camera_.eye + offPlane), camera_.forward};
    return {origin_, camera_.forward + offPlane};
}

Ray PixelRays::ray(int x, int y) const {
    const auto [origin, direction] = unrounded(x, y);
    return makeRay(origin, direction);
}

// The perspective camera the SIMD rays are made from (pixel_ray_rows.hpp); none for an
// orthographic one or an origin makeRay refuses, whose rays go one at a time.
std::optional<PerspectivePixels> PixelRays::simdPixels() const {
    if (orthographic_ || !finite(glm::dvec3(origin_))) return std::nullopt;
    return PerspectivePixels{.offset = offset_, .width = double(width_), .height = double(height_),
                             .halfHeight = halfHeight_, .aspect = aspect_, .right = right_,
                             .forward = camera_.forward, .up = camera_.up, .origin = origin_};
}

int PixelRays::rowRays(int y, int x0, int count, Ray* out) const {
    return simd_ ? perspectiveRowRays(*simd_, y, x0, count, out) : 0;
}

int PixelRays::tileDirections(int x0, int y0, Ray* out) const {
    return simd_ ? perspectiveTileDirections(*simd_, x0, y0, out) : 0;
}

namespace {

void primaryRayRow(const PixelRays& pixels, int width, int y, Ray* row) {
    for (int x = pixels.rowRays(y, 0, width, row); x < width; ++x) row[x] = pixels.ray(x, y);
}

}  // namespace

std::vector<Ray> primaryRays(const Camera& camera, int width, int height, glm::dvec2 offset) {
    std::vector<Ray> rays = mappedArray<Ray>(std::size_t(width) * std::size_t(height));
    const PixelRays pixels(camera, width, height, offset);
    for (int y = 0; y < height; ++y) primaryRayRow(pixels, width, y, &rays[std::size_t(y) * std::size_t(width)]);
    return rays;
}

void primaryRays(const Camera& camera, int width, int height, ThreadPool& pool, std::vector<Ray>& rays,
                 glm::dvec2 offset) {
    reserveMapped(rays, std::size_t(width) * std::size_t(height));
    rays.resize(std::size_t(width) * std::size_t(height));
    const PixelRays pixels(camera, width, height, offset);
    pool.parallelForRethrowing(std::size_t(height), [&](std::size_t y, unsigned) {
        primaryRayRow(pixels, width, int(y), &rays[y * std::size_t(width)]);
    });
}

}  // namespace dacrt
