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

class RayBatch {
public:
    // One ray per pixel centre, row-major from the top-left pixel, exactly as `dacrt render`
    // makes them for the scene and camera (so a trace gives the command line's hits).
    // width and height lie in 1..16384. Throws InputError on bad values.
    static RayBatch fromCamera(const TraceScene& scene, const CameraSpec& camera, int width, int height);

    // Rays from arrays of x, y, z: `origins` and `directions` (of any non-zero length: t is
    // measured in units of the normalized direction) three floats per ray; `tmin` and `tmax`
    // empty or one per ray: a hit has tmin < t <= tmax (defaults 0 and unbounded). Throws
    // InputError on sizes that do not match, a zero or non-finite direction, a non-finite
    // origin, or a segment with tmin < 0 or tmax < tmin.
    static RayBatch fromArrays(std::span<const float> origins, std::span<const float> directions,
                               std::span<const float> tmin = {}, std::span<const float> tmax = {});

    RayBatch(RayBatch&&) noexcept;
    RayBatch& operator=(RayBatch&&) noexcept;
    ~RayBatch();

    std::size_t size() const;

    struct Impl;  // the library's own

private:
    explicit RayBatch(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
    friend class Tracer;
};

}  // namespace dacrt
