// The Python module `dacrt`: numpy in, numpy out, on the public C++ API (include/dacrt/).
// This file only wires: the errors, the constants and the classes of the other files.
#include "bindings.hpp"

PYBIND11_MODULE(dacrt, m) {
    namespace py = pybind11;
    using namespace dacrt::python;
    m.doc() = R"(dacrt: divide-and-conquer ray tracing, with no acceleration structure, on the CPU and on
a Vulkan device; Embree and the device's ray queries as peers. docs/python.md is the manual.

    import numpy as np, dacrt
    scene = dacrt.Scene.from_gltf("scenes/room.glb")
    tracer = dacrt.Tracer("cpu")
    rays = np.array([[0, 1.3, 1.9, 0, -0.3, -1]], dtype=np.float32)   # origin, direction
    hits = tracer.cast_rays(scene, rays)        # t_hit, primitive_ids, primitive_uvs, primitive_normals

Bad input raises dacrt.InputError (a ValueError) with the library's message.)";
    m.attr("__version__") = DACRT_VERSION;
    // The library's two failures: bad input (a ValueError, as numpy's own) and a broken promise.
    py::register_exception<dacrt::InputError>(m, "InputError", PyExc_ValueError);
    py::register_exception<dacrt::InternalError>(m, "InternalError", PyExc_RuntimeError);
    m.attr("INVALID_ID") = dacrt::kNoPrimitive;  // primitive_ids of a ray that hit nothing
    bindScene(m);
    bindTracer(m);
    bindDevices(m);
}
