// dacrt.Scene: triangles from numpy arrays or a glTF file (TraceScene), and a camera's rays as
// an array.
#include <cstdint>
#include <vector>

#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "numpy_arrays.hpp"

namespace dacrt::python {

namespace {

// The library's single-sided flags from double_sided: True (every triangle two-sided: no
// flags), False (every one single-sided) or one bool per triangle.
std::vector<std::uint8_t> singleSidedFlags(const py::handle& doubleSided, std::size_t triangles) {
    if (py::isinstance<py::bool_>(doubleSided))
        return doubleSided.cast<bool>() ? std::vector<std::uint8_t>{} : std::vector<std::uint8_t>(triangles, 1);
    const Contiguous<bool> flags = valuesOf<bool>(doubleSided, "double_sided");
    if (flags.ndim() != 1 || std::size_t(flags.size()) != triangles)
        throw InputError("double_sided: " + std::to_string(flags.size()) + " values for " + std::to_string(triangles) +
                         " triangles (True, False or one bool per triangle)");
    std::vector<std::uint8_t> single(triangles);
    for (std::size_t k = 0; k < triangles; ++k) single[k] = flags.data()[k] ? 0 : 1;
    return single;
}

std::unique_ptr<SceneHandle> sceneFromArrays(const py::handle& vertices, const py::handle& triangles,
                                             const py::handle& doubleSided) {
    const Contiguous<float> v = rowsOf<float>(vertices, "vertices", 3);
    const Contiguous<std::uint32_t> t = rowsOf<std::uint32_t>(triangles, "triangles", 3);
    if (v.ndim() != 2) throw InputError("vertices: expected an array of shape (N, 3)");
    if (t.ndim() != 2) throw InputError("triangles: expected an array of shape (M, 3)");
    const std::vector<std::uint8_t> single = singleSidedFlags(doubleSided, std::size_t(t.shape(0)));
    py::gil_scoped_release release;
    return std::make_unique<SceneHandle>(TraceScene::fromArrays(spanOf(v), spanOf(t), single));
}

std::unique_ptr<SceneHandle> sceneFromGltf(const std::string& path, double time, const std::string& scene,
                                           const std::string& animation, const std::string& camera,
                                           const std::string& cull) {
    const std::optional<CullMode> mode = cullModeNamed(cull);
    if (!mode) {
        std::string names;
        for (const std::string& n : cullModeNames()) names += (names.empty() ? "" : ", ") + n;
        throw InputError("cull: '" + cull + "' is not a face rule (" + names + ")");
    }
    const SceneLoadOptions options{.scene = scene, .animation = animation, .time = time, .camera = camera, .cull = *mode};
    py::gil_scoped_release release;
    return std::make_unique<SceneHandle>(TraceScene::load(path, options));
}

void setPositions(SceneHandle& s, const py::handle& vertices) {
    const Contiguous<float> v = rowsOf<float>(vertices, "vertices", 3);
    if (v.ndim() != 2) throw InputError("vertices: expected an array of shape (N, 3)");
    py::gil_scoped_release release;
    std::scoped_lock lock(s.mutex);
    s.scene.setPositions(spanOf(v));
}

py::array_t<float> cameraRays(SceneHandle& s, int width, int height, const Point& eye, const Point& target,
                              const Point& up, std::optional<double> fov) {
    const RayBatch rays = cameraBatch(s, cameraOf(eye, target, up, fov), width, height);
    py::array_t<float> out(Shape{height, width, 6});
    float* data = out.mutable_data();
    py::gil_scoped_release release;
    rays.writeRays(std::span<float>(data, rays.size() * 6));
    return out;
}

}  // namespace

CameraSpec cameraOf(const Point& eye, const Point& target, const Point& up, std::optional<double> fovDegrees) {
    return CameraSpec{.eye = eye, .target = target, .up = up, .fovDegrees = fovDegrees};
}

RayBatch cameraBatch(SceneHandle& s, const CameraSpec& camera, int width, int height) {
    py::gil_scoped_release release;
    std::scoped_lock lock(s.mutex);
    return RayBatch::fromCamera(s.scene, camera, width, height);
}

void bindScene(py::module_& m) {
    py::class_<SceneHandle>(m, "Scene", R"(Triangles to trace, checked once.

Scene(vertices, triangles, double_sided=True): vertices (N, 3) float32, triangles (M, 3)
uint32 (indices into vertices), double_sided True, False or one bool per triangle (False: a
ray meeting the back face, where the vertices turn clockwise, passes through). Triangles
with no area are dropped; hits keep the caller's numbering (row k of triangles is
primitive k). Scene.from_gltf(path, ...) loads a glTF file.)")
        .def(py::init(&sceneFromArrays), py::arg("vertices"), py::arg("triangles"), py::arg("double_sided") = true)
        .def_static("from_gltf", &sceneFromGltf, py::arg("path"), py::arg("time") = 0.0, py::arg("scene") = "",
                    py::arg("animation") = "", py::arg("camera") = "", py::arg("cull") = "material",
                    R"(The file's scene (.gltf or .glb) as `dacrt render` loads it: at `time` seconds of its
animations (`animation`: an index or name; empty: all), `scene` and `camera` an index or
name (empty: the default scene, the first placed camera), `cull` the face rule: material
(glTF's doubleSided, the default), none or backfaces. Primitive ids follow the file's
order of nodes, meshes and primitives.)")
        .def("set_positions", &setPositions, py::arg("vertices"),
             R"(Moves the vertices of a scene made from arrays, for the next frame of an animation:
vertices (N, 3) float32, as many as the scene was made with; the triangles, their ids and
face rules stay. The next trace follows them (the gpu uploads them again; embree and
rayquery rebuild or refit). Raises dacrt.InputError, changing nothing, on another vertex
count, a coordinate that is not finite or beyond +-1e9, a triangle dropped for having no area
that has area now, and for a scene loaded from a file (load it again at the new time).)")
        .def_property_readonly("triangle_count", [](SceneHandle& s) { return s.scene.triangleCount(); },
                               "triangles traced (those with area)")
        .def_property_readonly("triangles_dropped", [](SceneHandle& s) { return s.scene.trianglesDropped(); },
                               "triangles with no area, dropped")
        .def_property_readonly(
            "bounds",
            [](SceneHandle& s) {
                const SceneBounds b = s.scene.bounds();
                return py::make_tuple(py::array_t<float>(3, b.lo.data()), py::array_t<float>(3, b.hi.data()));
            },
            "(lo, hi): the traced triangles' bounding box")
        .def("camera_rays", &cameraRays, py::arg("width"), py::arg("height"), py::arg("eye") = py::none(),
             py::arg("target") = py::none(), py::arg("up") = py::none(), py::arg("fov") = py::none(),
             R"(A camera's rays, one per pixel centre, as (height, width, 6) float32: origin, unit
direction, exactly as `dacrt render` makes them: the scene's camera (or the default view
framing its bounds) with eye, target, up (3 numbers each) and fov (vertical, degrees)
overriding it. cast_rays gives them render's hits bit for bit.)");
}

}  // namespace dacrt::python
