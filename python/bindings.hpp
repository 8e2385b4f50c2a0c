#pragma once
// The module's classes, one file each (scene_binding, tracer_binding, devices_binding), and
// what they share: a scene and a tracer with the lock that lets the tracing run without the
// GIL (the library's objects are used from one thread at a time).
#include <mutex>
#include <optional>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <dacrt/dacrt.hpp>

namespace dacrt::python {

namespace py = pybind11;

struct SceneHandle {
    explicit SceneHandle(TraceScene s) : scene(std::move(s)) {}
    TraceScene scene;
    std::mutex mutex;
};

struct TracerHandle {
    explicit TracerHandle(const TracerOptions& options) : tracer(options) {}
    Tracer tracer;
    std::mutex mutex;
    TraceTimings lastTimings;  // of the last trace, for last_timings
};

// The camera of camera_rays and render: the scene's (or the default view) with these overrides.
using Point = std::optional<std::array<double, 3>>;
CameraSpec cameraOf(const Point& eye, const Point& target, const Point& up, std::optional<double> fovDegrees);

// The camera's rays for the scene (RayBatch::fromCamera, which checks the size), made with the
// GIL released and the scene locked.
RayBatch cameraBatch(SceneHandle& s, const CameraSpec& camera, int width, int height);

void bindScene(py::module_& m);
void bindTracer(py::module_& m);
void bindDevices(py::module_& m);

}  // namespace dacrt::python
