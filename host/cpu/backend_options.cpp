#include "cpu/backend_options.hpp"

#include <array>
#include <vector>

#include "core/errors.hpp"

namespace dacrt {

namespace {

constexpr BackendSet kCpuDacrt{Backend::CpuSeq, Backend::Cpu};
constexpr BackendSet kDacrt{Backend::CpuSeq, Backend::Cpu, Backend::Gpu};
constexpr BackendSet kSubScenes{Backend::Cpu, Backend::Gpu};
constexpr BackendSet kGpu{Backend::Gpu};
constexpr BackendSet kEmbree{Backend::Embree};

constexpr bool kAdvanced = true;
constexpr bool kDacrtOption = true;

static_assert(kPassBatchRays == 65536 && kPassBatchRaysPerTriangle == 8, "--ray-grouping's help names the batch size");

// The order is the help's, and the order in which a refusal names the options.
constexpr std::array<BackendOption, 23> kBackendOptions{{
    {"--regions", kSubScenes, "sub-scenes", "default: one per thread, on gpu one per core of a CPU device (a secondary pass's rays there: one, with --ray-groups as the cpu backend's batches), 64 on a GPU",
     !kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return r.trace.regions != 0; }},
    {"--axis", kSubScenes, "division axis", "", !kAdvanced, !kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.axis != DivisionAxis::Best; }},
    {"--threads", {Backend::Brute, Backend::Cpu, Backend::Gpu, Backend::Embree}, "worker threads",
     "default: every core", !kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return r.trace.threads > 1; }},
    {"--ray-limit", kDacrt, "leaf when fewer live rays", "", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.rayLimit != 0; }},
    {"--tri-limit", kDacrt, "leaf when fewer triangles", "", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.triLimit != 0; }},
    {"--split", kCpuDacrt, "DACRT split", "gpu always splits at the spatial median", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.split != DacrtOptions{}.split; }},
    {"--split-cost", kCpuDacrt,
     "what makes a node a leaf: limits (--ray-limit, --tri-limit) or ray-sampling (Nabata et al. 2013: also where a "
     "sample of its rays and triangles estimates a leaf cheaper than any split; it then splits where, and on the axis where, "
     "that estimate is lowest)",
     "with packets, ray-sampling decides in the levels traced ray by ray", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.splitCost != DacrtOptions{}.splitCost; }},
    {"--intersector", kCpuDacrt, "leaf ray/triangle test", "", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.intersector != DacrtOptions{}.intersector; }},
    {"--triangle-filter", kCpuDacrt, "triangle/box filter: bounds, sat (exact separating axes) or mora (inexact)", "",
     !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.triangleFilter != DacrtOptions{}.triangleFilter; }},
    {"--precision", kCpuDacrt, "leaf ray/triangle arithmetic", "", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.precision != DacrtOptions{}.precision; }},
    {"--packets", kDacrt, "filter primary rays 8x8 pixels at a time high in the recursion, one by one below: on or off",
     "cpu: with the default tests only; gpu: not on a device with a loop limiter, such as lavapipe before Mesa 25",
     !kAdvanced, kDacrtOption, [](const RequestedOptions& r) { return r.trace.dacrt.packets != DacrtOptions{}.packets; }},
    {"--tight-boxes", kDacrt,
     "a node whose live rays number at least twice its triangles traces inside the box of its triangles' bounds "
     "rather than its whole cell: on or off",
     "", !kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.tightBoxes != DacrtOptions{}.tightBoxes; }},
    {"--packet-flush", kDacrt, "a node with fewer packets goes on ray by ray", "", kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.packetFlush != 0; }},
    {"--ray-grouping", kCpuDacrt,
     "how a secondary pass's rays are traced: batches (as made, pixel by pixel, in traces of at most 65536 rays each, "
     "or 8 per triangle of the scene where that is more; on cpu without --regions, a multiple of the threads in number, "
     "traced side by side, each on one thread), slots (as made, in one trace), octant (grouped by the signs "
     "of their directions) or octant-calls (each octant's group traced on its own)",
     "", kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.rayGrouping != DacrtOptions{}.rayGrouping; }},
    {"--pass-tracing", kCpuDacrt,
     "how a frame's secondary passes are traced: apart (each pass on its own, after its own pass cull), together "
     "(every pass's rays merged pixel by pixel into the same traces, which divide the triangles once) or auto "
     "(together where the passes make fewer rays than the scene has triangles)",
     "", kAdvanced, kDacrtOption,
     [](const RequestedOptions& r) { return r.trace.dacrt.passTracing != DacrtOptions{}.passTracing; }},
    {"--workgroup-size", kGpu, "invocations per workgroup", "default: per device", kAdvanced, !kDacrtOption,
     [](const RequestedOptions& r) { return r.workgroupSize != 0; }},
    {"--ray-groups", kGpu, "work items per region, each a band of its rays with its own copy of the region's triangle ids",
     "default: 2 on a CPU device with a loop limiter, such as lavapipe before Mesa 25, else 1, and where neither this nor --regions is given a secondary pass's rays on a CPU device are one region's groups, as many as --ray-grouping's batches; the discrete profile shares 2048 in all (given: G times the regions) out among the regions by estimated cost",
     kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return r.rayGroups != 0; }},
    {"--leaf-balance", kGpu,
     "a node is also a leaf where its ray/triangle tests number fewer than N per id a split would partition "
     "(rays x triangles < N x (rays + triangles)); 0: off",
     "default: 20 under the cpu profile where neither leaf limit is given (a limit not given is then off), else 0",
     kAdvanced,
     !kDacrtOption, [](const RequestedOptions& r) { return r.leafBalance.has_value(); }},
    {"--gpu-profile", kGpu,
     "whose defaults the regions, ray groups, workgroup size and leaf rule take where not given: auto (the device's kind), cpu "
     "(a CPU device's, as lavapipe's) or discrete (a discrete GPU's, at least 2048 work items in Step 1, on any device)",
     "default: auto", kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return r.gpuProfile != GpuProfile::Auto; }},
    {"--stage-clocks", kGpu,
     "run the kernel with clocks around its stages and report each stage's ticks in --stats (gpu.stage_ticks): "
     "the same hits, a little slower",
     "needs the device's subgroup clock (dacrt devices)", kAdvanced, !kDacrtOption,
     [](const RequestedOptions& r) { return r.stageClocks; }},
    {"--no-skip", {Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Gpu},
     "skips to turn off (each changes speed only): backfaces (single-sided triangles facing away from the camera, or "
     "from a directional light's shadow rays), "
     "frustum (triangles outside the view), uploads (gpu: triangle buffers kept across frames), subscenes (cpu: small "
     "frames traced as one sequential DACRT), passrays (secondary passes: triangles no ray of the pass comes near)",
     "", !kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return !(r.trace.skips == SkipSwitches{}); }},
    {"--embree-fast", kEmbree, "without RTC_SCENE_FLAG_ROBUST: faster, leaks through edges", "", !kAdvanced,
     !kDacrtOption, [](const RequestedOptions& r) { return !r.embreeRobust; }},
    {"--embree-single-rays", kEmbree, "one rtcIntersect1 per ray instead of 16-wide packets on 4x4 tiles", "",
     kAdvanced, !kDacrtOption, [](const RequestedOptions& r) { return !r.embreePackets; }},
}};

// Refuses the options of the table (its DacrtOptions rows alone with `dacrtOnly`) that the
// request gives a backend that does not take them, naming them all in one message.
void refuseOptionsNotTaken(const RequestedOptions& request, bool dacrtOnly) {
    const Backend backend = request.trace.backend;
    std::vector<std::string_view> refused;
    for (const BackendOption& o : kBackendOptions)
        if ((o.dacrtOption || !dacrtOnly) && o.given(request) && !o.takenBy.has(backend)) refused.push_back(o.flag);
    if (refused.empty()) return;
    std::string list;
    for (std::size_t i = 0; i < refused.size(); ++i)
        list += std::string(i == 0 ? "" : i + 1 == refused.size() ? " and " : ", ") + std::string(refused[i]);
    throw InputError(list + (refused.size() == 1 ? " is not an option of --backend " : " are not options of --backend ") +
                     toString(backend) + " (see dacrt render --help: each option names its backends)");
}

}  // namespace

std::string BackendSet::names() const {
    std::string out;
    for (const auto& [backend, name] : EnumNames<Backend>::table)
        if (has(backend)) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

std::span<const BackendOption> backendOptions() { return kBackendOptions; }

std::string backendOptionHelp(const BackendOption& option) {
    return std::string(option.help) + " (" + option.takenBy.names() +
           (option.note.empty() ? "" : "; " + std::string(option.note)) + ")";
}

void checkOptionCombinations(const DacrtOptions& dacrt) {
    if (dacrt.precision == Precision::F64 && dacrt.intersector != Intersector::Watertight)
        throw InputError("precision f64 runs the watertight test in float64; it does not combine with the " +
                         toString(dacrt.intersector) + " intersector");
    const bool byOctant = dacrt.rayGrouping == RayGrouping::Octant || dacrt.rayGrouping == RayGrouping::OctantCalls;
    if (dacrt.passTracing == PassTracing::Together && byOctant)
        throw InputError("--pass-tracing together merges the passes' rays pixel by pixel; it does not combine with "
                         "--ray-grouping " + toString(dacrt.rayGrouping));
}

void checkRequestedOptions(const RequestedOptions& request) {
    refuseOptionsNotTaken(request, false);
    checkOptionCombinations(request.trace.dacrt);
}

void checkTraceOptions(const TraceOptions& options) {
    refuseOptionsNotTaken(RequestedOptions{options}, true);
    checkOptionCombinations(options.dacrt);
}

}  // namespace dacrt
