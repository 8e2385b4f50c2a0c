#pragma once
// Cameras and primary rays. Ray directions are computed once here, in float32, and every
// backend traces exactly these rays.
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/pixel_ray_rows.hpp"
#include "core/scene.hpp"

namespace dacrt {

struct Camera {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};  // unit
    glm::dvec3 up{0.0, 1.0, 0.0};        // unit, orthogonal to forward
    double yfovRadians = 0.0;            // perspective
    Projection projection = Projection::Perspective;
    double ymag = 0.0;                   // orthographic: half the view's height
};

struct CameraOptions {
    std::optional<glm::dvec3> eye;
    std::optional<glm::dvec3> target;
    std::optional<glm::dvec3> up;
    std::optional<double> fovDegrees;  // vertical
    int orbit = 0;                     // 0: one camera; K > 0: K cameras on a circle
};

constexpr double kDefaultFovDegrees = 45.0;

// The scene's camera if it has one (perspective or orthographic), else a perspective front view
// (looking down -z) framing the box; options override it (eye or target: a perspective view). With orbit K, the K cameras are the base camera rotated about the
// vertical (y) axis through the box centre by 2 pi k / K. Throws InputError on bad values.
std::vector<Camera> makeCameras(const Scene& scene, const Box& bounds, const CameraOptions& options, double aspect);

// The side planes of the pyramid every primary ray of `camera` at width x height lies in, for
// any point of a pixel (primaryRays' offset in [0, 1]^2): planes through the rays' float32
// origin, unit normals pointing inward. Exact in real arithmetic (the pixel rectangle's edges);
// the rays' rounding to float32 moves them at most 2^-23 outside, which users must allow for.
// inward: the left, right, bottom and top planes. The camera's basis and the rows it was made
// for let rowsFrustum narrow it to a band of the image's rows.
struct ViewFrustum {
    glm::dvec3 apex{0.0};
    std::array<glm::dvec3, 4> inward{};
    glm::dvec3 forward{0.0}, up{0.0};
    double halfHeight = 0.0;  // tan(yfov / 2): the top row's edge is forward + halfHeight up
    int rows = 0;             // the image's height in pixels
};
// Empty for an orthographic camera, whose rays share no apex.
std::optional<ViewFrustum> viewFrustum(const Camera& camera, int width, int height);
// The pyramid the primary rays of pixel rows [firstRow, endRow) lie in, for any point of their
// pixels: `frustum` with its bottom and top planes through those rows' outer edges (the same
// bound, in real arithmetic, as the whole image's).
ViewFrustum rowsFrustum(const ViewFrustum& frustum, int firstRow, int endRow);

// Canonical float32 ray from an origin and a direction of any length: normalized in double,
// rounded to float, components below 2^-64 flushed to zero (so 1/dir <= 2^64), and the
// watertight-test permutation and shear precomputed. Throws InputError on a zero or
// non-finite direction or origin.
Ray makeRay(const glm::vec3& origin, const glm::dvec3& direction, float tmin = 0.0f);

// primaryRays' arithmetic a pixel or a row's span at a time, for primaryRays itself and for a
// tracer that makes each ray where it traces it (the Embree peer's packets,
// peers/embree_in_loop.hpp), never storing a frame of rays: ray(x, y) is primaryRays' ray of
// pixel (x, y) bit for bit.
class PixelRays {
public:
    PixelRays(const Camera& camera, int width, int height, glm::dvec2 offset = {0.5, 0.5});

    int width() const { return width_; }
    int height() const { return height_; }

    Ray ray(int x, int y) const;

    // The rays of pixels x0 .. x0 + count - 1 of row y into out[0 ..], several pixels per
    // instruction (pixel_ray_rows.hpp), each ray(x, y) bit for bit: returns how many it made
    // from the left (all, or 0 for an orthographic camera, or those before a pixel left to
    // makeRay); ray(x, y) makes the rest.
    int rowRays(int y, int x0, int count, Ray* out) const;
    // The 4x4 tile's rays from pixel (x0, y0), lane l the pixel (x0 + l % 4, y0 + l / 4), their
    // origin and dir alone, ray(x, y)'s bit for bit (no other field is made): returns how many
    // it made, as rowRays.
    int tileDirections(int x0, int y0, Ray* out) const;

private:
    std::optional<PerspectivePixels> simdPixels() const;
    // The ray's float32 origin and its direction before makeRay rounds it.
    std::pair<glm::vec3, glm::dvec3> unrounded(int x, int y) const;

    Camera camera_;
    int width_ = 1, height_ = 1;
    glm::dvec2 offset_;
    glm::dvec3 right_;
    double aspect_ = 1.0, halfHeight_ = 0.0;
    bool orthographic_ = false;
    glm::vec3 origin_;
    std::optional<PerspectivePixels> simd_;
};

// One ray per pixel through the point `offset` of the pixel (in pixel units from its top-left
// corner; the centre by default), row-major from the top-left pixel. Perspective rays start at
// the eye; orthographic rays all travel along forward, from the pixel's point of the plane
// through the eye (2 ymag high, the image's aspect wide), with tmin 0.
std::vector<Ray> primaryRays(const Camera& camera, int width, int height, glm::dvec2 offset = {0.5, 0.5});
// The same rays, rows on every thread of pool, into rays (resized; reusing its memory).
void primaryRays(const Camera& camera, int width, int height, ThreadPool& pool, std::vector<Ray>& rays,
                 glm::dvec2 offset = {0.5, 0.5});

}  // namespace dacrt
