// dacrt.Tracer: a backend with its threads (and device), tracing numpy rays into a Scene with
// the GIL released: cast_rays (closest hits), test_occlusions (any hit), render (a camera's
// hits as images).
#include <cmath>
#include <limits>
#include <string>

#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "hit_arrays.hpp"
#include "numpy_arrays.hpp"

namespace dacrt::python {

namespace {

Backend backendOf(const std::string& name) {
    if (const std::optional<Backend> b = backendNamed(name)) return *b;
    std::string names;
    for (const std::string& n : backendNames()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("backend: '" + name + "' is not a backend (" + names + ")");
}

TracerOptions tracerOptions(const std::string& backend, unsigned threads, const std::string& device, bool validate) {
    TracerOptions o;
    o.trace.backend = backendOf(backend);
    o.trace.threads = threads;
    o.device = device;
    o.validate = validate;
    return o;
}

std::unique_ptr<TracerHandle> makeTracer(const std::string& backend, unsigned threads, const std::string& device,
                                         bool validate) {
    const TracerOptions options = tracerOptions(backend, threads, device, validate);
    py::gil_scoped_release release;  // opening a Vulkan device takes a while
    return std::make_unique<TracerHandle>(options);
}

// The caller's rays (..., 6), read in place where C-contiguous float32, and their segments.
struct RayArrays {
    Contiguous<float> rays;
    Shape shape;  // the rays' shape without the last axis: the results' shape
    SegmentBound tmin, tmax;
    DirectionLength length;
};

RayArrays rayArraysOf(const py::handle& rays, const py::handle& tmin, const py::handle& tmax, bool normalize) {
    RayArrays r{rowsOf<float>(rays, "rays", 6), {}, {}, {}, normalize ? DirectionLength::Normalize : DirectionLength::AsGiven};
    r.shape = leadingShape(r.rays);
    r.tmin = segmentBoundOf(tmin, "tmin", r.shape, 0.0f);
    r.tmax = segmentBoundOf(tmax, "tmax", r.shape, std::numeric_limits<float>::infinity());
    return r;
}

enum class Query { Closest, Any };

// Traces the rays `makeBatch` makes on the tracer and scene, each locked, with the GIL released
// (making them reads the caller's arrays, which the caller's references keep alive), and hands
// the output to `use`, still without the GIL.
template <typename MakeBatch, typename UseOutput>
void traceWithoutGil(TracerHandle& t, SceneHandle& s, Query query, MakeBatch makeBatch, UseOutput use) {
    py::gil_scoped_release release;
    std::scoped_lock lock(t.mutex, s.mutex);
    const RayBatch batch = makeBatch();
    const TraceOutput out = query == Query::Any ? t.tracer.occluded(s.scene, batch) : t.tracer.trace(s.scene, batch);
    t.lastTimings = out.timings;
    use(out);
}

py::dict castRays(TracerHandle& t, SceneHandle& s, const py::handle& rays, const py::handle& tmin,
                  const py::handle& tmax, bool normalize) {
    const RayArrays r = rayArraysOf(rays, tmin, tmax, normalize);
    HitArrays hits(r.shape);
    traceWithoutGil(
        t, s, Query::Closest, [&] { return RayBatch::fromRays(spanOf(r.rays), r.tmin.values, r.tmax.values, r.length); },
        [&](const TraceOutput& out) { hits.fill(out.hits, s.scene); });
    return hits.toDict();
}

py::array_t<bool> testOcclusions(TracerHandle& t, SceneHandle& s, const py::handle& rays, const py::handle& tmin,
                                 const py::handle& tmax, bool normalize) {
    const RayArrays r = rayArraysOf(rays, tmin, tmax, normalize);
    py::array_t<bool> occluded = arrayOf<bool>(r.shape);
    bool* data = occluded.mutable_data();
    traceWithoutGil(
        t, s, Query::Any, [&] { return RayBatch::fromRays(spanOf(r.rays), r.tmin.values, r.tmax.values, r.length); },
        [&](const TraceOutput& out) {
            for (std::size_t i = 0; i < out.hits.size(); ++i) data[i] = out.hits[i].hit();
        });
    return occluded;
}

py::dict render(TracerHandle& t, SceneHandle& s, int width, int height, const Point& eye, const Point& target,
                const Point& up, std::optional<double> fov) {
    // Made first: the library checks the size before the images are allocated.
    RayBatch batch = cameraBatch(s, cameraOf(eye, target, up, fov), width, height);
    HitArrays hits(Shape{height, width});
    traceWithoutGil(
        t, s, Query::Closest, [&] { return std::move(batch); },
        [&](const TraceOutput& out) { hits.fill(out.hits, s.scene); });
    return hits.toDict();
}

// Another backend or thread count on the tracer's threads and device (Tracer::setOptions).
void setOptions(TracerHandle& t, const std::string& backend, unsigned threads) {
    TracerOptions o = t.tracer.options();
    o.trace.backend = backendOf(backend);
    o.trace.threads = threads;
    py::gil_scoped_release release;
    std::scoped_lock lock(t.mutex);
    t.tracer.setOptions(o);
}

py::dict timingsOf(const TraceTimings& timings) {
    py::dict d;
    for (const auto& [name, ms] : {std::pair{"total_ms", timings.totalMs}, {"skips_ms", timings.skipsMs},
                                   {"divide_ms", timings.divideMs}, {"step1_ms", timings.step1Ms},
                                   {"transfer_ms", timings.transferMs}, {"build_ms", timings.buildMs},
                                   {"allocate_ms", timings.allocateMs}, {"upload_ms", timings.uploadMs},
                                   {"pipeline_compile_ms", timings.pipelineCompileMs},
                                   {"dispatch_ms", timings.dispatchMs}, {"readback_ms", timings.readbackMs},
                                   {"trace_ms", timings.traceMs}})
        d[name] = ms;
    return d;
}

}  // namespace

void bindTracer(py::module_& m) {
    const float inf = std::numeric_limits<float>::infinity();
    py::class_<TracerHandle>(m, "Tracer", R"(A backend with its threads (and, for gpu and rayquery, its Vulkan device), opened
once and kept for every trace.

Tracer(backend="cpu", threads=0, device="", validate=False): backend one of brute,
cpu-seq, cpu, gpu, embree, rayquery (dacrt.backends() lists those this machine runs);
threads 0 for every core (cpu-seq and rayquery take no thread count); device a Vulkan
device's index or part of its name (gpu, rayquery; empty: the best); validate runs them
under the Vulkan validation layers. brute, cpu-seq, cpu and gpu give the same primitive ids
and t bit for bit; embree and rayquery are peers with their own answers.)")
        .def(py::init(&makeTracer), py::arg("backend") = "cpu", py::arg("threads") = 0u, py::arg("device") = "",
             py::arg("validate") = false)
        .def("cast_rays", &castRays, py::arg("scene"), py::arg("rays"), py::arg("tmin") = 0.0f, py::arg("tmax") = inf,
             py::arg("normalize") = false,
             R"(Each ray's closest hit within tmin < t <= tmax.

rays: (..., 6) float32, origin x, y, z then direction x, y, z per ray (read in place when
C-contiguous); tmin, tmax: a number or an array shaped as rays[..., 0]. t is in units of
the direction as given (Open3D's and Embree's rule); normalize=True makes it a distance
along the normalized direction. Returns a dict of arrays shaped as the rays: t_hit (float32,
inf on a miss), primitive_ids (uint32, INVALID_ID on a miss), primitive_uvs (..., 2)
(barycentric weights of the second and third vertex), primitive_normals (..., 3) (the hit
triangle's unit geometric normal, cross(v1 - v0, v2 - v0)). The GIL is released while
tracing.)")
        .def("test_occlusions", &testOcclusions, py::arg("scene"), py::arg("rays"), py::arg("tmin") = 0.0f,
             py::arg("tmax") = inf, py::arg("normalize") = false,
             "Whether anything lies on each ray within tmin < t <= tmax: a bool array shaped as rays[..., 0].")
        .def("render", &render, py::arg("scene"), py::arg("width"), py::arg("height"), py::arg("eye") = py::none(),
             py::arg("target") = py::none(), py::arg("up") = py::none(), py::arg("fov") = py::none(),
             R"(The camera's primary hits as images, as `dacrt render --aov` writes them: the dict of
cast_rays with arrays of shape (height, width[, k]); t_hit is the AOV's Z, primitive_ids
its primId, primitive_uvs its u, v and primitive_normals its N. The camera as for
Scene.camera_rays.)")
        .def_property(
            "backend", [](TracerHandle& t) { return backendName(t.tracer.options().trace.backend); },
            [](TracerHandle& t, const std::string& b) { setOptions(t, b, t.tracer.options().trace.threads); },
            "the backend; setting it traces the next rays on another, on the same threads and device")
        .def_property(
            "threads", [](TracerHandle& t) { return t.tracer.options().trace.threads; },
            [](TracerHandle& t, unsigned n) { setOptions(t, backendName(t.tracer.options().trace.backend), n); },
            "worker threads (0: every core)")
        .def_property_readonly("device", [](TracerHandle& t) { return t.tracer.device(); },
                               "the Vulkan device opened, 'name (driver)'; empty where none is")
        .def_property_readonly("validation_errors", [](TracerHandle& t) { return t.tracer.validationErrors(); })
        .def_property_readonly("last_timings", [](TracerHandle& t) { return timingsOf(t.lastTimings); },
                               "the last trace's phases in milliseconds, measured on the host");
}

}  // namespace dacrt::python
