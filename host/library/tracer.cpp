// The public Tracer: the options become a BackendRequest and a DeviceChoice, and every trace
// goes through the BackendDispatcher, as the command line's do.
#include <dacrt/tracer.hpp>

#include <optional>

#include <dacrt/errors.hpp>

#include "core/system_memory.hpp"
#include "core/timing.hpp"
#include "library/api_results.hpp"
#include "library/api_state.hpp"
#include "library/backend_dispatcher.hpp"

namespace dacrt {

struct Tracer::Impl {
    TracerOptions options;
    BackendRequest request;
    BackendDispatcher dispatcher;

    explicit Impl(const TracerOptions& o)
        : options(o),
          request(checkedRequest(o)),
          dispatcher(checkedDevices(o), {o.trace.backend}) {}

    static BackendRequest checkedRequest(const TracerOptions& o) {
        BackendRequest r{.trace = o.trace, .gpuTuning = o.gpu, .embree = o.embree};
        checkBackendRequest(r);
        return r;
    }
    static DeviceChoice checkedDevices(const TracerOptions& o) {
        DeviceChoice d{o.device, o.validate};
        checkDeviceChoice(d, {o.trace.backend});
        return d;
    }
};

namespace {

// The frame of a batch: a camera's keeps its image width and view frustum (the frustum skip);
// any-hit rays are traced as a secondary pass's are.
FrameGeometry frameOf(const TraceScene::Impl& s, const RayBatch::Impl& r, HitQuery query) {
    FrameGeometry g = query == HitQuery::Any
                          ? secondaryFrame(s.scene.triangles, s.triangleBounds, r.rays, s.box)
                          : frameGeometry(s.scene.triangles, s.triangleBounds, r.rays, s.box, r.imageWidth);
    if (query == HitQuery::Closest) g.frustum = r.frustum;
    g.trianglesVersion = s.scene.trianglesVersion;
    return g;
}

TraceOutput traced(BackendDispatcher& dispatcher, const BackendRequest& request, const TraceScene::Impl& s,
                   const RayBatch::Impl& r, HitQuery query) {
    if (r.rays.empty()) return {};  // nothing to trace (a frame reads its first ray)
    const auto start = Clock::now();
    // As dacrt render does: a plan larger than this machine's memory is refused before it is allocated.
    const PlanHook fitsInMemory = [](const MemoryPlan& plan) {
        checkFitsInMemory("the trace", plan.total(), "trace the rays in smaller batches");
        return true;
    };
    const TraceResult result = dispatcher.trace(frameOf(s, r, query), request, fitsInMemory);
    return traceOutputOf(result, s.callerIds, msSince(start));
}

}  // namespace

Tracer::Tracer(const TracerOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Tracer::Tracer(Tracer&&) noexcept = default;
Tracer& Tracer::operator=(Tracer&&) noexcept = default;
Tracer::~Tracer() = default;

TraceOutput Tracer::trace(const TraceScene& scene, const RayBatch& rays) {
    return traced(impl_->dispatcher, impl_->request, *scene.impl_, *rays.impl_, HitQuery::Closest);
}

TraceOutput Tracer::occluded(const TraceScene& scene, const RayBatch& rays) {
    return traced(impl_->dispatcher, impl_->request, *scene.impl_, *rays.impl_, HitQuery::Any);
}

FramePlan Tracer::plan(const TraceScene& scene, const RayBatch& rays) {
    if (impl_->options.trace.backend == Backend::Embree)
        throw InputError("embree allocates its BVH itself, so dacrt has no memory plan for it");
    if (rays.impl_->rays.empty()) return {};
    std::optional<MemoryPlan> planned;
    const PlanHook stopAtPlan = [&planned](const MemoryPlan& p) {
        planned = p;
        return false;  // stop before anything is traced
    };
    impl_->dispatcher.trace(frameOf(*scene.impl_, *rays.impl_, HitQuery::Closest), impl_->request, stopAtPlan);
    if (!planned) throw InternalError("the backend traced without showing its plan first");
    return framePlanOf(*planned);
}

void Tracer::setOptions(const TracerOptions& options) {
    if (options.device != impl_->options.device || options.validate != impl_->options.validate)
        throw InputError("the Vulkan device and its validation are chosen when a Tracer is made: make another Tracer "
                         "for another choice");
    if (runsOnVulkan(options.trace.backend) && !impl_->dispatcher.gpuContext())
        throw InputError(toString(options.trace.backend) +
                         " runs on a Vulkan device, which this Tracer did not open: make it with gpu or rayquery");
    impl_->request = Impl::checkedRequest(options);
    impl_->options = options;
}

const TracerOptions& Tracer::options() const { return impl_->options; }

std::string Tracer::device() const {
    const gpu::Context* gpu = impl_->dispatcher.gpuContext();
    return gpu ? gpu->info().name + " (" + gpu->info().driver + ")" : std::string();
}

std::uint32_t Tracer::validationErrors() const { return impl_->dispatcher.validationErrors(); }

}  // namespace dacrt
