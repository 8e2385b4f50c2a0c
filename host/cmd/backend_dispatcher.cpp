#include "cmd/backend_dispatcher.hpp"

#include <algorithm>
#include <ostream>
#include <thread>

#include "cmd/exit_codes.hpp"
#include "core/errors.hpp"
#include "dacrt/cpu_tracers.hpp"
#include "oracle/embree_tracer.hpp"

namespace dacrt {

void checkBackendRequest(const BackendRequest& r) {
    const Backend b = r.trace.backend;
    if (b != Backend::Gpu && (r.gpuTuning.workgroupSize || r.gpuTuning.rayGroups))
        throw InputError("--workgroup-size and --ray-groups tune the gpu backend; --backend " + toString(b) +
                         " has no workgroups");
    if ((b == Backend::Embree || b == Backend::Brute) && !r.trace.dacrt.exactDefaults())
        throw InputError("--intersector, --triangle-filter and --precision are DACRT options of cpu and cpu-seq; " +
                         toString(b) + (b == Backend::Brute ? " always runs the watertight float32 test"
                                                            : " has its own test"));
    if (b != Backend::Embree && !r.embreeRobust)
        throw InputError("--embree-fast is an option of --backend embree, not " + toString(b));
    if (b == Backend::Gpu) checkGpuOptions(r.trace);
    if (b == Backend::Brute || b == Backend::CpuSeq || b == Backend::Cpu) checkCpuOptions(r.trace);
}

BackendDispatcher::BackendDispatcher(const DeviceChoice& devices, const std::vector<Backend>& backends)
    : devices_(devices) {
    if (std::find(backends.begin(), backends.end(), Backend::Gpu) != backends.end()) {
        gpu_ = std::make_unique<gpu::Context>(gpu::ContextOptions{devices.device, devices.validate});
        pipelines_ = std::make_unique<gpu::PipelineCache>(*gpu_);
    }
}

BackendDispatcher::~BackendDispatcher() = default;

unsigned BackendDispatcher::threadsOf(const TraceOptions& options) {
    if (options.backend == Backend::CpuSeq) return 1;
    return options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
}

ThreadPool& BackendDispatcher::pool(unsigned threads) {
    std::unique_ptr<ThreadPool>& p = pools_[threads];
    if (!p) p = std::make_unique<ThreadPool>(threads);
    return *p;
}

TraceResult BackendDispatcher::trace(const FrameGeometry& geometry, const BackendRequest& request,
                                     const PlanHook& onPlan) {
    checkBackendRequest(request);
    const unsigned threads = threadsOf(request.trace);
    ThreadPool& threadPool = pool(threads);
    switch (request.trace.backend) {
        case Backend::Gpu:
            if (!gpu_) throw InternalError("the gpu backend was asked for a trace without a device being opened");
            return traceGpu(geometry, request.trace, request.gpuTuning, *gpu_, threadPool, onPlan, pipelines_.get());
        case Backend::Embree:
            // Embree allocates its BVH itself: there is no plan to show or check.
            return traceEmbree(geometry, EmbreeOptions{request.embreeRobust, threads}, threadPool);
        case Backend::Brute:
        case Backend::CpuSeq:
        case Backend::Cpu: return traceCpu(geometry, request.trace, threadPool, onPlan);
    }
    throw InternalError("unknown backend");
}

std::uint32_t BackendDispatcher::validationErrors() const { return gpu_ ? gpu_->validationErrors() : 0; }

int BackendDispatcher::validationEpilogue(std::ostream& err) const {
    if (!gpu_ || !devices_.validate || gpu_->validationErrors() == 0) return kExitSuccess;
    for (const std::string& m : gpu_->validationMessages()) err << "dacrt: validation " << m << "\n";
    err << "dacrt: error: " << gpu_->validationErrors() << " Vulkan validation errors\n";
    return kExitValidation;
}

}  // namespace dacrt
