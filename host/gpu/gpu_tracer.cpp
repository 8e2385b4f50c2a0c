#include "gpu/gpu_tracer.hpp"

#include <algorithm>
#include <functional>
#include <limits>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "cpu/backend_options.hpp"
#include "cpu/scene_division.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/dispatch_recorder.hpp"
#include "gpu/work_plan.hpp"

namespace dacrt {

// What a primary pass leaves on the device for the frame's secondary passes, and what the
// first of those adds for the others.
struct GpuPassSource {
    std::uint64_t primaryRays = 0;
    std::unique_ptr<gpu::DacrtBindingSet> primary;  // its rays, hits, triangles and bounds
    // The triangles' division for secondary rays (their rays are binned on the device), its
    // work plan, every ray group's copy of the triangle ids, and the workgroup size.
    bool divided = false;
    Division division;
    gpu::WorkPlan work;
    std::unique_ptr<gpu::Buffer> triangleIds;
    std::uint32_t workgroupSize = 0;
    float margin = 0.0f;
};

void GpuPassSourceDeleter::operator()(GpuPassSource* source) const { delete source; }

namespace {

// What the frame's stages hand each other.
struct GpuFrame {
    const FrameGeometry& geometry;
    Division division;
    std::vector<TransferRound> schedule;
    gpu::WorkPlan work;
    std::uint32_t workgroupSize = 0;
    gpu::DacrtBufferPlan buffers{};
    gpu::ResidentTriangles* resident = nullptr;  // the uploads skip: triangles kept on the device
    bool trianglesOnDevice = false;              // resident holds this frame's already
};

void describeDevice(const gpu::DeviceInfo& device, TraceResult& result) {
    result.gpu = GpuReport{};
    result.gpu->device = device.name;
    result.gpu->driver = device.driver;
    result.gpu->subgroupSize = device.subgroupSize;
}

// The same division as the cpu backend, then the work items over the region slots.
void planWorkItems(GpuFrame& frame, const TraceOptions& options, const GpuTuning& tuning,
                   const gpu::DeviceInfo& device, ThreadPool& pool, MemoryPlan& hostPlan, TraceResult& result) {
    const auto start = Clock::now();
    const unsigned regions = options.regions ? options.regions : gpu::defaultGpuRegions(device);
    const int axis =
        options.axis == DivisionAxis::Best ? chooseDivisionAxis(frame.geometry, regions) : int(options.axis) - 1;
    frame.division = divideScene(frame.geometry, regions, axis, pool, hostPlan);
    frame.schedule = transferSchedule(frame.division);
    const std::uint32_t groups = tuning.rayGroups ? tuning.rayGroups : gpu::defaultRayGroups(device, regions);
    frame.work = gpu::planWorkItems(frame.division, frame.schedule, groups);
    result.regions = regions;
    result.axis = axis;
    result.counters.raysCulled = frame.division.culledRays;
    result.gpu->rayGroups = groups;
    result.phaseMs.emplace_back("divide", msSince(start));
}

std::uint32_t chooseWorkgroupSize(const gpu::WorkPlan& work, const GpuTuning& tuning, const gpu::DeviceInfo& device,
                                  TraceResult& result) {
    const std::uint32_t size = tuning.workgroupSize
                                   ? tuning.workgroupSize
                                   : gpu::defaultWorkgroupSize(device, work.largestSlotRays, work.largestSlotTriangles);
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = gpu::widestWorkgroup(device);
    if (size % subgroup != 0 || size > widest)
        throw InputError("a workgroup size of " + std::to_string(size) + " does not suit this device: it must be a " +
                         "multiple of the subgroup size " + std::to_string(subgroup) + " and at most " +
                         std::to_string(widest));
    result.gpu->workgroupSize = size;
    return size;
}

// Every buffer, host and device, from the counts; checked against the device's limits.
void planMemory(GpuFrame& frame, const gpu::DeviceInfo& device, const MemoryPlan& hostPlan, const DacrtOptions& options,
                TraceResult& result) {
    const std::uint64_t triIdCount = std::uint64_t(frame.division.triIds.size()) * frame.work.groups;
    frame.buffers = gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
        .rays = frame.geometry.rays->size(),
        .triangles = frame.geometry.triangles->size(),
        .rayIds = frame.division.rayIds.size(),
        .triangleIds = triIdCount,
        .regions = frame.work.slots.size(),
        .workItems = frame.work.items.size(),
        .maxDepth = options.maxDepth,
    });
    for (const auto& [name, bytes] : hostPlan.buffers) result.memory.add("host: " + name, bytes);
    result.memory.add("host: triangle ids per ray group", triIdCount * 4);
    gpu::addToMemoryPlan(frame.buffers, device, result.memory);
    result.memory.work.insert(result.memory.work.end(), hostPlan.work.begin(), hostPlan.work.end());
    const FrameGeometry& g = frame.geometry;
    result.memory.addWork("gpu work items", frame.work.items.size(), "Step 1 and transfer pairs, per ray group");
    const std::uint64_t triangleBytes = std::uint64_t(g.triangles->size()) * (sizeof(Triangle) + sizeof(Bounds));
    const std::uint64_t uploaded = std::uint64_t(g.rays->size()) * (sizeof(Ray) + sizeof(Hit)) +
                                   (frame.trianglesOnDevice ? 0 : triangleBytes) +
                                   std::uint64_t(frame.division.rayIds.size()) * 4 + triIdCount * 4 +
                                   frame.work.slots.size() * sizeof(Region) + frame.work.items.size() *
                                   (sizeof(WorkItem) + sizeof(TraversalState)) + sizeof(GpuCounters);
    result.memory.addWork("bytes uploaded", uploaded, "rays, misses, triangles and bounds, ids, regions, work items");
    result.memory.addWork("skipped: triangle and bounds upload (bytes)", frame.trianglesOnDevice ? triangleBytes : 0,
                          frame.resident ? (frame.trianglesOnDevice ? "on the device since an earlier frame" : "uploaded, kept for the next frame")
                                         : g.trianglesVersion ? "skip off (--no-skip uploads)" : "the triangles' version is unknown");
    result.memory.addWork("bytes read back", std::uint64_t(g.rays->size()) * sizeof(Hit) + frame.work.slots.size() * sizeof(Region),
                          "hits and regions");
}

// Creates the frame's buffers and fills them.
gpu::DacrtBindingSet uploadFrame(const GpuFrame& frame, const gpu::Context& context, TraceResult& result) {
    const auto start = Clock::now();
    gpu::ResidentBuffers resident{};
    if (frame.resident) {
        frame.resident->prepare(context, frame.geometry);
        resident[DACRT_BINDING_TRIANGLES] = &frame.resident->triangles();
        resident[DACRT_BINDING_TRIANGLE_BOUNDS] = &frame.resident->bounds();
    }
    gpu::DacrtBindingSet set(context, frame.buffers, resident);
    const FrameGeometry& g = frame.geometry;
    const std::vector<std::uint32_t> slotTriIds = gpu::groupTriangleIds(frame.division, frame.work.groups);
    std::vector<Hit> misses;
    misses.reserve(g.rays->size());
    for (const Ray& ray : *g.rays) misses.push_back(missHit(ray));
    const GpuCounters zero{};
    const std::vector<TraversalState> fresh(frame.work.items.size(), TraversalState{});
    auto upload = [&](std::uint32_t binding, const auto& v) { set[binding].upload(v.data(), v.size() * sizeof(v[0])); };
    upload(DACRT_BINDING_RAYS, *g.rays);
    if (!frame.resident) {
        upload(DACRT_BINDING_TRIANGLES, *g.triangles);
        upload(DACRT_BINDING_TRIANGLE_BOUNDS, *g.triangleBounds);
    }
    upload(DACRT_BINDING_HITS, misses);
    upload(DACRT_BINDING_RAY_IDS, frame.division.rayIds);
    upload(DACRT_BINDING_TRI_IDS, slotTriIds);
    upload(DACRT_BINDING_REGIONS, frame.work.slots);
    upload(DACRT_BINDING_WORK_ITEMS, frame.work.items);
    set[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    upload(DACRT_BINDING_STATES, fresh);
    result.phaseMs.emplace_back("upload", msSince(start));
    return set;
}

gpu::ComputePipeline& preparePipeline(std::uint32_t workgroupSize, bool sharedStart, bool anyHit, const DacrtOptions& options,
                                      const gpu::DeviceInfo& device, gpu::PipelineCache& pipelines,
                                      const gpu::DacrtBindingSet& set, TraceResult& result) {
    const auto start = Clock::now();
    const DacrtOptions leafLimits = options.resolvedFor(Backend::Gpu);
    gpu::ComputePipeline& pipeline = pipelines.kernel(gpu::KernelSpecialization{
        .workgroupSize = workgroupSize,
        .rayLimit = leafLimits.rayLimit,
        .triLimit = leafLimits.triLimit,
        .maxDepth = options.maxDepth,
        .loopBudget = gpu::loopBudgetOf(device),
        .sharedStart = sharedStart,
        .anyHit = anyHit,
    });
    // Compilation only (a first use; later frames find the pipeline in the cache), so that
    // render and bench can take it out of the frame.
    result.phaseMs.emplace_back(kPipelinePhase, msSince(start));
    set.bindTo(pipeline);
    return pipeline;
}

DacrtPush framePush(const GpuFrame& frame) {
    DacrtPush push{};
    push.rayOrigin = frame.geometry.nearSide;  // the shared origin when raysShareStart
    push.margin = frame.geometry.margin;
    push.axis = std::uint32_t(frame.division.axis);
    push.rayScratchHalf = std::uint32_t(frame.division.rayIds.size());
    push.triScratchHalf = std::uint32_t(frame.division.triIds.size() * frame.work.groups);
    push.loopProbe = 2;
    push.rayTmin = frame.geometry.rays->front().tmin;
    push.order = frame.geometry.order == ChildOrder::PerRay ? shared::kOrderPerRay : shared::kOrderNearSide;
    return push;
}

// A slice cut short by the loop limiter has left its work item in an unknown state, so this
// is checked first, after every submission.
void checkLoopLimit(const GpuCounters& counters, std::size_t items, const gpu::DeviceInfo& device) {
    if (counters.loopLimitHits > 0)
        throw InternalError(std::to_string(counters.loopLimitHits) + " of " + std::to_string(items) +
                            " work item slices were cut short by the driver's loop limit (" + device.driver +
                            " ends every shader invocation after 65535 loop iterations in all); the kernel's cost " +
                            "estimates undercount this scene: please report it (docs/gpu.md)");
}

// Records `count` work items from `first` as dispatches of at most maxComputeWorkGroupCountX.
void recordPass(gpu::DispatchRecorder& recorder, const std::string& name, gpu::ComputePipeline& pipeline,
                DacrtPush& push, std::uint32_t first, std::uint32_t count, std::uint32_t perDispatch) {
    for (std::uint32_t done = 0; done < count; done += perDispatch) {
        push.firstWorkItem = first + done;
        recorder.dispatch(name, pipeline, std::min(perDispatch, count - done), &push);
    }
}

std::uint32_t dispatchesFor(std::uint32_t count, std::uint32_t perDispatch) { return (count + perDispatch - 1) / perDispatch; }

void submit(gpu::DispatchRecorder& recorder, const gpu::DacrtBindingSet& set, GpuCounters& counters, GpuReport& report) {
    recorder.submitAndWait();
    for (const auto& t : recorder.timingsMs()) report.dispatchMs.push_back(t);
    set[DACRT_BINDING_COUNTERS].download(&counters, sizeof(counters));
}

// Dispatches recorded before the schedule in its command buffer (a secondary pass's ray making).
struct Prelude {
    std::uint32_t dispatches = 0;
    std::function<void(gpu::DispatchRecorder&)> record;
};

// One command buffer: the prelude, Step 1, then each transfer round, one pass each.
GpuCounters dispatchSchedule(const gpu::WorkPlan& work, gpu::Context& context, gpu::ComputePipeline& pipeline,
                             const gpu::DacrtBindingSet& set, DacrtPush& push, GpuReport& report,
                             const Prelude& prelude = {}) {
    const std::uint32_t perDispatch = context.info().maxComputeWorkGroupCountX;
    std::uint32_t dispatchCount = prelude.dispatches;
    for (const auto& pass : work.passes) dispatchCount += dispatchesFor(pass.second, perDispatch);
    gpu::DispatchRecorder recorder(context, dispatchCount);
    if (prelude.record) prelude.record(recorder);
    std::uint32_t first = 0;
    for (const auto& [name, count] : work.passes) {
        recordPass(recorder, name, pipeline, push, first, count, perDispatch);
        first += count;
    }
    GpuCounters counters{};
    submit(recorder, set, counters, report);
    return counters;
}

// A work item that ran out of loop budget (llvmpipe) is finished by continuation dispatches
// over all work items, submitted until every one is done.
void dispatchContinuations(const gpu::WorkPlan& work, gpu::Context& context, gpu::ComputePipeline& pipeline,
                           const gpu::DacrtBindingSet& set, DacrtPush& push, GpuCounters& counters, GpuReport& report) {
    constexpr std::uint32_t kContinuationsPerSubmit = 8;
    const gpu::DeviceInfo& device = context.info();
    const std::uint32_t items = std::uint32_t(work.items.size());
    const std::uint32_t perDispatch = device.maxComputeWorkGroupCountX;
    while (counters.itemsFinished < items) {
        checkLoopLimit(counters, items, device);
        if (counters.tooLarge > 0)
            throw InputError(std::to_string(counters.tooLarge) + " work items have a single step larger than the loop " +
                             "budget of " + std::to_string(gpu::loopBudgetOf(device)) + " iterations (" + device.driver +
                             "); use a larger workgroup size or more regions (docs/gpu.md)");
        const std::uint32_t slicesBefore = counters.slices;
        gpu::DispatchRecorder recorder(context, kContinuationsPerSubmit * dispatchesFor(items, perDispatch));
        for (std::uint32_t c = 0; c < kContinuationsPerSubmit; ++c)
            recordPass(recorder, "continuation", pipeline, push, 0, items, perDispatch);
        submit(recorder, set, counters, report);
        if (counters.slices == slicesBefore)
            throw InternalError("gpu work items stopped making progress (" + std::to_string(counters.itemsFinished) +
                                " of " + std::to_string(items) + " finished): please report it");
    }
}

void readBack(const gpu::WorkPlan& work, std::size_t rayCount, const gpu::DacrtBindingSet& set, const GpuCounters& counters,
              const gpu::Context& context, TraceResult& result) {
    const auto start = Clock::now();
    result.hits.resize(rayCount);
    set[DACRT_BINDING_HITS].download(result.hits.data(), result.hits.size() * sizeof(Hit));
    std::vector<Region> after(work.slots.size());
    set[DACRT_BINDING_REGIONS].download(after.data(), after.size() * sizeof(Region));
    result.phaseMs.emplace_back("readback", msSince(start));

    checkLoopLimit(counters, work.items.size(), context.info());
    result.counters.rayBoxTests = counters.rayBoxTests;
    result.counters.rayTriangleTests = counters.rayTriangleTests;
    result.counters.leaves = counters.leaves;
    result.counters.raysRetired = counters.raysRetired;
    result.counters.terminatedStep1 = counters.terminatedStep1;
    result.counters.transferWorkItems = work.transferPairs;
    GpuReport& report = *result.gpu;
    report.raysFinished = 0;  // one command buffer: no per-round readback
    for (const Region& r : after) report.raysFinished += r.terminated - r.rayBegin;
    report.dispatches = std::uint32_t(report.dispatchMs.size());
    report.slices = counters.slices;
    report.workItemsRun = counters.workItemsRun;
    report.workItemsEmpty = counters.workItemsEmpty;
    report.validationErrors = context.validationErrors();
}

}  // namespace

void checkGpuOptions(const TraceOptions& options) { checkTraceOptions(options); }

TraceResult traceGpu(const FrameGeometry& geometry, const TraceOptions& options, const GpuTuning& tuning,
                     gpu::Context& context, ThreadPool& pool, const PlanHook& onPlan, gpu::PipelineCache* pipelines,
                     gpu::ResidentTriangles* resident, GpuPassSourcePtr* keep) {
    const gpu::DeviceInfo& device = context.info();
    checkGpuOptions(options);
    if (!device.subgroupOperations)
        throw InputError("device '" + device.name +
                         "' lacks subgroup arithmetic or shuffles in compute shaders, which the gpu backend needs");
    TraceResult result;
    result.threads = pool.size();
    describeDevice(device, result);

    GpuFrame frame{geometry, {}, {}, {}, 0, {}};
    if (resident && options.skips.uploads && geometry.trianglesVersion != 0) {
        frame.resident = resident;
        frame.trianglesOnDevice = resident->holds(geometry);
    }
    MemoryPlan hostPlan;
    planWorkItems(frame, options, tuning, device, pool, hostPlan, result);
    frame.workgroupSize = chooseWorkgroupSize(frame.work, tuning, device, result);
    planMemory(frame, device, hostPlan, options.dacrt, result);
    if (onPlan && !onPlan(result.memory)) return result;

    gpu::DacrtBindingSet set = uploadFrame(frame, context, result);
    gpu::PipelineCache frameOnly(context);
    gpu::ComputePipeline& pipeline =
        preparePipeline(frame.workgroupSize, geometry.raysShareStart, geometry.query == HitQuery::Any, options.dacrt, device,
                        pipelines ? *pipelines : frameOnly, set, result);

    const auto start = Clock::now();
    DacrtPush push = framePush(frame);
    GpuCounters counters = dispatchSchedule(frame.work, context, pipeline, set, push, *result.gpu);
    dispatchContinuations(frame.work, context, pipeline, set, push, counters, *result.gpu);
    result.phaseMs.emplace_back("dispatch", msSince(start));

    readBack(frame.work, geometry.rays->size(), set, counters, context, result);
    if (keep) {
        *keep = GpuPassSourcePtr(new GpuPassSource{});
        (*keep)->primaryRays = geometry.rays->size();
        (*keep)->primary = std::make_unique<gpu::DacrtBindingSet>(std::move(set));
    }
    return result;
}

}  // namespace dacrt

namespace dacrt {
namespace {

// Secondary rays start on the surfaces, at most kOffsetSteps float32 steps of the triangles'
// coordinates off them (shaders/secondary_rays.glsl): a bound on their origins for the filter
// margin, which the host cannot take from rays it never sees.
float secondaryMargin(const Box& box) {
    glm::vec3 farthest(0.0f);
    for (int a = 0; a < 3; ++a) farthest[a] = std::max(std::abs(box.lo[a]), std::abs(box.hi[a])) * (1.0f + 0x1p-12f);
    return filterMargin(box, farthest);
}

// The first secondary pass of a frame divides its triangles (rays: none yet) and plans work
// items for every pair of regions, since rays of every direction may move between any two.
void divideForSecondaryRays(GpuPassSource& source, const FrameGeometry& frame, const TraceOptions& options,
                            const GpuTuning& tuning, gpu::Context& context, ThreadPool& pool, TraceResult& result) {
    const auto start = Clock::now();
    const gpu::DeviceInfo& device = context.info();
    const unsigned regions = options.regions ? options.regions : gpu::defaultGpuRegions(device);
    const glm::vec3 extent = frame.sceneBox.extent();
    const int longest = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const int axis = options.axis == DivisionAxis::Best ? longest : int(options.axis) - 1;
    static const std::vector<Ray> noRays;
    FrameGeometry triangles = frame;
    triangles.rays = &noRays;
    triangles.tracedTriangles = nullptr;
    // The margin the kernel and the device's ray binning filter with: triangles straddle by it.
    source.margin = secondaryMargin(frame.sceneBox);
    triangles.margin = source.margin;
    MemoryPlan unused;
    source.division = divideScene(triangles, regions, axis, pool, unused);
    const std::uint32_t groups = tuning.rayGroups ? tuning.rayGroups : gpu::defaultRayGroups(device, regions);
    source.work = gpu::planWorkItems(source.division, transferSchedule(source.division, false), groups);
    const std::vector<std::uint32_t> ids = gpu::groupTriangleIds(source.division, groups);
    const std::uint64_t idBytes = std::max<std::uint64_t>(ids.size(), 1) * 8;
    if (idBytes > device.maxStorageBufferRange)
        throw InputError("the device buffer of the secondary passes' triangle ids and scratch needs " +
                         std::to_string(idBytes) + " bytes, more than the device's maxStorageBufferRange of " +
                         std::to_string(device.maxStorageBufferRange) + " bytes (over by " +
                         std::to_string(idBytes - device.maxStorageBufferRange) + "); use fewer regions or ray groups");
    source.triangleIds = std::make_unique<gpu::Buffer>(context, idBytes, "triangle ids and scratch (secondary passes)");
    source.triangleIds->upload(ids.data(), ids.size() * sizeof(std::uint32_t));
    source.divided = true;
    result.phaseMs.emplace_back("divide", msSince(start));
}

SecondaryPush secondaryPush(const GpuPassSource& source, const SecondaryPass& pass) {
    SecondaryPush push{};
    push.light = pass.light;
    push.kind = pass.kind;
    push.sourceCount = std::uint32_t(source.primaryRays);
    push.raysPerHit = pass.raysPerHit;
    push.firstSample = pass.firstSample;
    push.samplesPerHit = pass.samplesPerHit ? pass.samplesPerHit : pass.raysPerHit;
    push.occlusionDistance = pass.occlusionDistance;
    push.sampleSeed = pass.sampleSeed;
    push.regionCount = std::uint32_t(source.division.regions.size());
    push.groups = source.work.groups;
    push.axis = std::uint32_t(source.division.axis);
    push.margin = source.margin;
    return push;
}

// The rays made, counted, ranged and filed by region slot: shaders/secondary.comp's three
// steps, each as many dispatches as the device's group count limit needs.
Prelude makeRaysOnDevice(gpu::ComputePipeline& pipeline, const SecondaryPush& base, std::uint64_t slots,
                         std::uint32_t perDispatch) {
    struct Step {
        const char* name;
        std::uint32_t step;
        std::uint64_t invocations;
    };
    const std::vector<Step> steps = {{"make rays", 0, slots}, {"ray ranges", 1, 1}, {"ray ids", 2, slots}};
    const std::uint64_t perGroupDispatch = std::uint64_t(perDispatch) * gpu::kSecondaryWorkgroup;
    Prelude prelude;
    for (const Step& s : steps) prelude.dispatches += std::uint32_t((s.invocations + perGroupDispatch - 1) / perGroupDispatch);
    prelude.record = [&pipeline, base, steps, perGroupDispatch](gpu::DispatchRecorder& recorder) {
        for (const Step& s : steps)
            for (std::uint64_t first = 0; first < s.invocations; first += perGroupDispatch) {
                SecondaryPush push = base;
                push.step = s.step;
                push.firstInvocation = std::uint32_t(first);
                const std::uint64_t count = std::min(perGroupDispatch, s.invocations - first);
                recorder.dispatch(s.name, pipeline, std::uint32_t((count + gpu::kSecondaryWorkgroup - 1) / gpu::kSecondaryWorkgroup),
                                  &push);
            }
    };
    return prelude;
}

}  // namespace

TraceResult traceGpuSecondary(GpuPassSource& source, const FrameGeometry& frame, const SecondaryPass& pass,
                              const TraceOptions& options, const GpuTuning& tuning, gpu::Context& context,
                              ThreadPool& pool, const PlanHook& onPlan, gpu::PipelineCache* pipelines) {
    const gpu::DeviceInfo& device = context.info();
    checkGpuOptions(options);
    TraceResult result;
    result.threads = pool.size();
    describeDevice(device, result);
    if (!source.divided) divideForSecondaryRays(source, frame, options, tuning, context, pool, result);
    const std::uint64_t slots = secondarySlots(pass, source.primaryRays);
    result.regions = unsigned(source.division.regions.size());
    result.axis = source.division.axis;
    result.gpu->rayGroups = source.work.groups;

    // Ray counts per slot are the device's to find: the estimate for the workgroup size is an
    // even share.
    gpu::WorkPlan sizing = source.work;
    sizing.largestSlotRays = std::uint32_t(std::min<std::uint64_t>(slots / std::max<std::size_t>(sizing.slots.size(), 1),
                                                                   std::numeric_limits<std::uint32_t>::max()));
    const std::uint32_t workgroupSize = chooseWorkgroupSize(sizing, tuning, device, result);
    const std::uint64_t triIdCount = std::uint64_t(source.division.triIds.size()) * source.work.groups;
    const gpu::DacrtBufferPlan buffers = gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
        .rays = slots,
        .triangles = frame.triangles->size(),
        .rayIds = slots,
        .triangleIds = triIdCount,
        .regions = source.work.slots.size(),
        .workItems = source.work.items.size(),
        .maxDepth = options.dacrt.maxDepth,
        .sourceRays = source.primaryRays,
    });
    // The buffers this pass shares with the primary pass: counted once, as kept.
    gpu::ResidentBuffers resident{};
    gpu::DacrtBindingSet& primary = *source.primary;
    resident[DACRT_BINDING_TRIANGLES] = &primary[DACRT_BINDING_TRIANGLES];
    resident[DACRT_BINDING_TRIANGLE_BOUNDS] = &primary[DACRT_BINDING_TRIANGLE_BOUNDS];
    resident[DACRT_BINDING_TRI_IDS] = source.triangleIds.get();
    resident[DACRT_BINDING_SOURCE_RAYS] = &primary[DACRT_BINDING_RAYS];
    resident[DACRT_BINDING_SOURCE_HITS] = &primary[DACRT_BINDING_HITS];
    gpu::addToMemoryPlan(buffers, device, result.memory, &resident);
    std::uint64_t kept = source.triangleIds->size();
    for (std::uint32_t k = 0; k < DACRT_BINDING_COUNT; ++k) kept += primary[k].size();
    result.memory.add("device: kept from the primary pass (its rays, hits, triangles and work buffers)", kept);
    result.memory.addWork("rays made on the device", slots,
                          std::to_string(pass.raysPerHit) + " per primary hit, where the surface can send one");
    result.memory.addWork("gpu work items", source.work.items.size(), "Step 1 and every pair of regions, per ray group");
    if (onPlan && !onPlan(result.memory)) return result;

    auto start = Clock::now();
    gpu::DacrtBindingSet set(context, buffers, resident);
    const GpuCounters zero{};
    const std::vector<TraversalState> fresh(source.work.items.size(), TraversalState{});
    set[DACRT_BINDING_REGIONS].upload(source.work.slots.data(), source.work.slots.size() * sizeof(Region));
    set[DACRT_BINDING_WORK_ITEMS].upload(source.work.items.data(), source.work.items.size() * sizeof(WorkItem));
    set[DACRT_BINDING_STATES].upload(fresh.data(), fresh.size() * sizeof(TraversalState));
    set[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    result.phaseMs.emplace_back("upload", msSince(start));

    gpu::PipelineCache frameOnly(context);
    gpu::PipelineCache& cache = pipelines ? *pipelines : frameOnly;
    gpu::ComputePipeline& kernel =
        preparePipeline(workgroupSize, false, true, options.dacrt, device, cache, set, result);
    start = Clock::now();
    gpu::ComputePipeline& maker = cache.secondary();
    set.bindTo(maker);
    result.phaseMs.emplace_back(kPipelinePhase, msSince(start));

    start = Clock::now();
    DacrtPush push{};
    push.margin = source.margin;
    push.axis = std::uint32_t(source.division.axis);
    push.rayScratchHalf = std::uint32_t(slots);
    push.triScratchHalf = std::uint32_t(triIdCount);
    push.loopProbe = 2;
    push.order = shared::kOrderPerRay;  // any hit: every ray visits the low child, then the high
    const Prelude prelude = makeRaysOnDevice(maker, secondaryPush(source, pass), slots, device.maxComputeWorkGroupCountX);
    GpuCounters counters = dispatchSchedule(source.work, context, kernel, set, push, *result.gpu, prelude);
    dispatchContinuations(source.work, context, kernel, set, push, counters, *result.gpu);
    result.phaseMs.emplace_back("dispatch", msSince(start));
    readBack(source.work, slots, set, counters, context, result);
    return result;
}

}  // namespace dacrt
