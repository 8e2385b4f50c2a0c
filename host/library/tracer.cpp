// The public Tracer: the options become a BackendRequest and a DeviceChoice, and every trace
// goes through the BackendDispatcher, which keeps the peers' structures from trace to trace.
#include <dacrt/tracer.hpp>

#include <optional>

#include <dacrt/errors.hpp>

#include "core/system_memory.hpp"
#include "core/timing.hpp"
#include "gpu/device_defaults.hpp"
#include "library/api_results.hpp"
#include "library/api_state.hpp"
#include "library/backend_dispatcher.hpp"
#include "library/frame_passes.hpp"

namespace dacrt {

struct Tracer::Impl {
    TracerOptions options;
    BackendRequest request;
    BackendDispatcher dispatcher;
    // The triangles' bounds of the frame being traced (dacrt's backends), their memory reused
    // from trace to trace.
    std::vector<Bounds> bounds;
    // The same in columns, for the cpu backends' triangle filters (FrameGeometry::boundsColumns).
    std::vector<float> boundsColumns;

    explicit Impl(const TracerOptions& o)
        : options(o),
          request(checkedRequest(o)),
          dispatcher(checkedDevices(o), {o.trace.backend}) {}

    static BackendRequest checkedRequest(const TracerOptions& o) {
        BackendRequest r{.trace = o.trace, .gpuTuning = o.gpu, .embree = o.embree, .rayQueryBuild = o.rayQueryBuild};
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

// The trace's threads, which also take the passes over its rays and hits (one for cpu-seq).
ThreadPool& tracePool(Tracer::Impl& t) { return t.dispatcher.pool(BackendDispatcher::threadsOf(t.request.trace)); }

// The frame of a batch: a camera's keeps its image width and view frustum (the frustum skip);
// any-hit rays are traced as a secondary pass's are. dacrt's backends read the triangles'
// bounds, made here on the trace's threads: dacrt keeps no structure between traces, so each
// one pays for what a frame of a dynamic scene needs (the peers, which build their own, do not).
// boundsMs: the time they took (0 for a peer).
FrameGeometry frameOf(Tracer::Impl& t, const TraceScene::Impl& s, const RayBatch::Impl& r, HitQuery query,
                      double& boundsMs) {
    const auto start = Clock::now();
    Box box = s.box;
    ThreadPool& pool = tracePool(t);
    const Backend backend = t.request.trace.backend;
    const bool columns = backend == Backend::Cpu || backend == Backend::CpuSeq;
    if (isPeer(backend)) t.bounds.clear();
    else triangleBoundsInParallel(s.scene.triangles, pool, t.bounds, box, columns ? &t.boundsColumns : nullptr);
    boundsMs = isPeer(t.request.trace.backend) ? 0.0 : msSince(start);
    FrameGeometry g = query == HitQuery::Any ? secondaryFrame(s.scene.triangles, t.bounds, r.rays, box, &pool)
                                             : frameGeometry(s.scene.triangles, t.bounds, r.rays, box, r.imageWidth, &pool,
                                                             r.pinholeRays);
    if (query == HitQuery::Closest) g.frustum = r.frustum;
    if (columns) g.boundsColumns = &t.boundsColumns;
    g.trianglesVersion = s.scene.trianglesVersion;
    g.sceneId = s.id;
    return g;
}

// The bounds' time as the trace's first phase.
TraceResult withBoundsPhase(TraceResult result, double boundsMs) {
    if (boundsMs > 0.0) result.phases.bounds = boundsMs;
    return result;
}

TraceOutput traced(Tracer::Impl& t, const TraceScene::Impl& s, const RayBatch::Impl& r, HitQuery query) {
    if (r.rays.empty()) return {};  // nothing to trace (a frame reads its first ray)
    const auto start = Clock::now();
    double boundsMs = 0.0;
    const FrameGeometry g = frameOf(t, s, r, query, boundsMs);
    // As dacrt render does: a plan larger than this machine's memory is refused before it is allocated.
    const PlanHook fitsInMemory = [](const MemoryPlan& plan) {
        checkFitsInMemory("the trace", plan.total(), "trace the rays in smaller batches");
        return true;
    };
    const TraceResult result = withBoundsPhase(t.dispatcher.trace(g, t.request, fitsInMemory), boundsMs);
    return traceOutputOf(result, s.callerIds, msSince(start), &tracePool(t));
}

// The caller's plan callback as the backends call it.
PlanHook planHookOf(const PlanCallback& onPlan) {
    if (!onPlan) return {};
    return [&onPlan](const MemoryPlan& plan) { return onPlan(framePlanOf(plan)); };
}

std::vector<PassOutput> passOutputsOf(std::vector<TracedPass> traced, const TraceScene::Impl& s, ThreadPool& pool) {
    std::vector<PassOutput> out;
    for (TracedPass& t : traced)
        out.push_back({framePassOf(t.pass), traceOutputOf(t.result, s.callerIds, t.ms, &pool), t.rays, t.ms, t.tracedIn});
    return out;
}

}  // namespace

void checkTracerOptions(const TracerOptions& options) {
    Tracer::Impl::checkedRequest(options);
    Tracer::Impl::checkedDevices(options);
}

unsigned traceThreads(const TraceOptions& options) { return BackendDispatcher::threadsOf(options); }

Tracer::Tracer(const TracerOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Tracer::Tracer(Tracer&&) noexcept = default;
Tracer& Tracer::operator=(Tracer&&) noexcept = default;
Tracer::~Tracer() = default;

TraceOutput Tracer::trace(const TraceScene& scene, const RayBatch& rays) {
    return traced(*impl_, *scene.impl_, *rays.impl_, HitQuery::Closest);
}

TraceOutput Tracer::occluded(const TraceScene& scene, const RayBatch& rays) {
    return traced(*impl_, *scene.impl_, *rays.impl_, HitQuery::Any);
}

FrameOutput Tracer::traceFrame(const TraceScene& scene, const RayBatch& cameraRays, const std::vector<FramePass>& passes,
                               const PlanCallback& onPlan, const ProgressCallback& onProgress) {
    FrameOutput out;
    if (cameraRays.impl_->rays.empty()) return out;
    const TraceScene::Impl& s = *scene.impl_;
    const auto start = Clock::now();
    double boundsMs = 0.0;
    const FrameGeometry g = frameOf(*impl_, s, *cameraRays.impl_, HitQuery::Closest, boundsMs);
    BackendRequest request = impl_->request;
    request.keepForPasses = !passes.empty();  // gpu: the passes start from the device's hits
    const PlanHook hook = planHookOf(onPlan);
    const TraceResult primary = withBoundsPhase(impl_->dispatcher.trace(g, request, hook, onProgress), boundsMs);
    out.stoppedAtPlan = primary.hits.empty();
    if (out.stoppedAtPlan) return out;
    out.primary = traceOutputOf(primary, s.callerIds, msSince(start), &tracePool(*impl_));
    std::vector<SecondaryPass> secondary;
    for (const FramePass& pass : passes) secondary.push_back(secondaryPassOf(pass));
    out.passes = passOutputsOf(traceSecondaryPasses(secondary, g, primary.hits, impl_->dispatcher, request, hook), s,
                               tracePool(*impl_));
    out.stoppedAtPlan = out.passes.size() < passes.size();
    return out;
}

FramePlan Tracer::plan(const TraceScene& scene, const RayBatch& rays) {
    if (rays.impl_->rays.empty()) return {};
    std::optional<MemoryPlan> planned;
    const PlanHook stopAtPlan = [&planned](const MemoryPlan& p) {
        planned = p;
        return false;  // stop before anything is traced
    };
    double boundsMs = 0.0;
    impl_->dispatcher.trace(frameOf(*impl_, *scene.impl_, *rays.impl_, HitQuery::Closest, boundsMs), impl_->request,
                            stopAtPlan);
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

void Tracer::releaseKept() { impl_->dispatcher.releaseKept(); }

const TracerOptions& Tracer::options() const { return impl_->options; }

std::string Tracer::device() const {
    const gpu::Context* gpu = impl_->dispatcher.gpuContext();
    return gpu ? gpu->info().name + " (" + gpu->info().driver + ")" : std::string();
}

std::optional<VulkanDeviceProperties> Tracer::deviceProperties() const {
    const gpu::Context* gpu = impl_->dispatcher.gpuContext();
    if (!gpu) return std::nullopt;
    return static_cast<const VulkanDeviceProperties&>(gpu->info());
}

std::optional<Tracer::GpuDefaults> Tracer::gpuDefaults() const {
    const gpu::Context* gpu = impl_->dispatcher.gpuContext();
    if (!gpu) return std::nullopt;
    const GpuProfile profile = impl_->options.gpu.profile;
    const unsigned regions = gpu::defaultGpuRegions(gpu->info(), profile);
    return GpuDefaults{regions, gpu::defaultRayGroups(gpu->info(), profile, regions),
                       gpu::kernelLeafRule(DacrtOptions{}, GpuTuning{.profile = profile}, gpu->info()).leafBalance};
}

std::uint32_t Tracer::validationErrors() const { return impl_->dispatcher.validationErrors(); }

std::vector<std::string> Tracer::validationMessages() const {
    const gpu::Context* gpu = impl_->dispatcher.gpuContext();
    return gpu ? gpu->validationMessages() : std::vector<std::string>();
}

}  // namespace dacrt
