#pragma once
// Rays to trace: a camera's, one per pixel, or any origins and directions with their segments.
#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>

#include <dacrt/scene.hpp>

namespace dacrt {

// What overrides the scene's camera (or, without one, the default front view framing the
// scene's bounds): as dacrt render's --eye, --target, --up and --fov.
struct CameraSpec {
    std::optional<std::array<double, 3>> eye;
    std::optional<std::array<double, 3>> target;
    std::optional<std::array<double, 3>> up;
    std::optional<double> fovDegrees;  // vertical
};

// What t measures along a ray given as arrays.
enum class DirectionLength {
    // The direction is normalized (in double precision, then rounded to float): t is a
    // distance, whatever length the caller's direction had.
    Normalize,
    // The direction is traced as given: t is measured in units of its length, as in Embree's
    // rays. A segment from o to a point p is the direction p - o with tmax 1 (a shadow ray
    // towards a point light, whose end then needs no square root); a direction the caller
    // made unit in float32 stays bit for bit the one traced.
    AsGiven,
};

class RayBatch {
public:
    // One ray per pixel centre, row-major from the top-left pixel, exactly as `dacrt render`
    // makes them for the scene and camera (so a trace gives the command line's hits).
    // width and height lie in 1..16384. Throws InputError on bad values, or a batch larger than
    // this machine's memory.
    static RayBatch fromCamera(const TraceScene& scene, const CameraSpec& camera, int width, int height);

    // Rays from arrays of x, y, z: `origins` and `directions` three floats per ray; `tmin`
    // and `tmax` empty or one per ray: a hit has tmin < t <= tmax (defaults 0 and unbounded;
    // +infinity is unbounded too). `length` says what t measures (DirectionLength). Each
    // component of the traced direction below 2^-64 in magnitude is taken as 0. Throws InputError on sizes
    // that do not match, a non-finite origin or direction, a zero direction (with AsGiven: one
    // whose largest component lies outside 2^-64 .. 2^62), a segment with tmin < 0 or
    // tmax < tmin, or more rays than this machine's memory holds.
    static RayBatch fromArrays(std::span<const float> origins, std::span<const float> directions,
                               std::span<const float> tmin = {}, std::span<const float> tmax = {},
                               DirectionLength length = DirectionLength::Normalize);

    // The same from one array of six floats per ray, origin x, y, z then direction x, y, z
    // (Open3D's and numpy's (..., 6) layout, read in place), with the same rules and messages;
    // InputError on a size that is not whole rays.
    static RayBatch fromRays(std::span<const float> rays, std::span<const float> tmin = {},
                             std::span<const float> tmax = {}, DirectionLength length = DirectionLength::Normalize);

    RayBatch(RayBatch&&) noexcept;
    RayBatch& operator=(RayBatch&&) noexcept;
    ~RayBatch();

    std::size_t size() const;

    // The rays as traced, six floats per ray into `rays` (6 * size() of them): the origin, then
    // the direction (unit length, or as given with DirectionLength::AsGiven; components below
    // 2^-64 flushed to 0). Traced again with AsGiven, they give the same hits bit for bit: a
    // camera's rays so become arrays for fromRays. InputError on another size.
    void writeRays(std::span<float> rays) const;

    struct Impl;  // the library's own

private:
    explicit RayBatch(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
    friend class Tracer;
};

}  // namespace dacrt
