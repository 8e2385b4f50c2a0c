#include "gpu/gpu_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "cpu/backend_options.hpp"
#include "cpu/scene_division.hpp"
#include "cpu/traversal.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/dispatch_recorder.hpp"
#include "gpu/ray_cost_estimate.hpp"
#include "gpu/ray_packets.hpp"
#include "gpu/stage_clocks.hpp"
#include "gpu/work_plan.hpp"
#include "gpu/work_spread.hpp"

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

PassCapacity secondaryPassCapacity(const GpuPassSource* source, const gpu::BufferLimits& limits) {
    if (!limits.addresses)
        return {limits.bindingBytes / sizeof(Ray), "one binding of rays (" + limits.bindingLimit + ", " +
                                                        std::to_string(limits.bindingBytes) + " bytes) on a device " +
                                                        "without bufferDeviceAddress"};
    // The ray ids and their scratch half: 2 of the kernels' 32-bit indices a slot, at most 2^31.
    PassCapacity c{std::uint64_t(1) << 30, "the ray ids' 32-bit indices"};
    std::uint64_t kept = 0;
    if (source) {
        for (std::uint32_t k = 0; k < DACRT_BINDING_COUNT; ++k) kept += (*source->primary)[k].size();
        if (source->triangleIds) kept += source->triangleIds->size();
    }
    constexpr std::uint64_t kSlotBytes = sizeof(Ray) + sizeof(Hit) + 2 * sizeof(std::uint32_t);  // rays, hits, ray ids
    const std::uint64_t left = limits.memoryBytes > kept ? limits.memoryBytes - kept : 0;
    if (limits.memoryBytes && left / 2 / kSlotBytes < c.slots)
        c = {left / 2 / kSlotBytes, "half the " + limits.memoryLimit + " (" + std::to_string(limits.memoryBytes) +
                                        " bytes) left by the primary pass's " + std::to_string(kept) + " bytes"};
    return c;
}

// What a frame's (or a secondary pass's) stages hand each other.
struct GpuTracer::Frame {
    const FrameGeometry& geometry;
    TraceResult result;
    std::uint64_t rays = 0;                 // rays traced (a secondary pass: its slots)
    MemoryPlan hostPlan;                    // the division's buffers and work lines
    Division division;                      // a primary frame's (a pass traces its source's)
    gpu::WorkPlan ownWork;
    const gpu::WorkPlan* work = &ownWork;   // a secondary pass: its source's
    std::optional<gpu::RayPackets> packets; // where the kernel traces packets (kernelUsesPackets)
    std::uint32_t workgroupSize = 0;
    std::uint64_t triIdCount = 0;           // triangle ids over every ray group
    gpu::DacrtBufferPlan buffers{};
    std::uint64_t stackSlots = 0;           // traversal stacks kept between slices (stackSlotsFor)
    gpu::ResidentBuffers kept{};            // bound from elsewhere: resident triangles, the primary pass's
    bool trianglesOnDevice = false;         // resident_ holds this frame's already (uploads skip)
    bool keepsTriangles = false;            // the uploads skip applies: triangles kept on the device
    std::unique_ptr<gpu::DacrtBindingSet> set;
    gpu::ComputePipeline* kernel = nullptr;
    gpu::ComputePipeline* rayMaker = nullptr;  // a secondary pass's
    GpuCounters counters{};
};

namespace {

void describeDevice(const gpu::DeviceInfo& device, TraceResult& result) {
    result.gpu = GpuReport{};
    result.gpu->device = device.name;
    result.gpu->driver = device.driver;
    result.gpu->subgroupSize = device.subgroupSize;
}

std::uint32_t chooseWorkgroupSize(const gpu::WorkPlan& work, const GpuTuning& tuning, const gpu::DeviceInfo& device,
                                  TraceResult& result) {
    const std::uint32_t size = tuning.workgroupSize
                                   ? tuning.workgroupSize
                                   : gpu::defaultWorkgroupSize(device, tuning.profile, work.largestSlotRays, work.largestSlotTriangles);
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = gpu::widestWorkgroup(device);
    const double need = gpu::stepWorkgroupNeed(device, work.largestSlotRays, work.largestSlotTriangles);
    if (!tuning.workgroupSize && need > widest) {
        // Fewer triangles per frame shrink the step: the caller may trace them in batches.
        const std::uint64_t needed = std::uint64_t(std::ceil(need));
        throw gpu::DeviceLimitExceeded(
            "the largest region's single step (" + std::to_string(work.largestSlotRays) + " rays, " +
                std::to_string(work.largestSlotTriangles) + " triangles) needs a workgroup of about " +
                std::to_string(needed) + " invocations to fit the loop budget of " +
                std::to_string(gpu::loopBudgetOf(device)) + " iterations (" + device.driver + "), more than the widest, " +
                std::to_string(widest) + "; use more regions (--regions)",
            "loop budget of one step (workgroup invocations)", needed, widest);
    }
    if (size % subgroup != 0 || size > widest)
        throw InputError("a workgroup size of " + std::to_string(size) + " does not suit this device: it must be a " +
                         "multiple of the subgroup size " + std::to_string(subgroup) + " and at most " +
                         std::to_string(widest));
    result.gpu->workgroupSize = size;
    return size;
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

// A work item that saved its stack past the buffer's last slot cannot resume: checked after
// every submission, as the loop limit.
void checkStackSlots(const GpuCounters& counters, std::uint32_t slots) {
    if (counters.stackSlotsTaken > slots)
        throw InputError(std::to_string(counters.stackSlotsTaken) + " work items ran out of the loop budget and saved " +
                         "their traversal stacks, more than the " + std::to_string(slots) + " the device's largest " +
                         "buffer holds; use fewer regions or ray groups (docs/gpu.md)");
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
    const std::vector<std::pair<std::string, std::uint32_t>> passes = gpu::dispatchedPasses(work);
    std::uint32_t dispatchCount = prelude.dispatches;
    for (const auto& pass : passes) dispatchCount += dispatchesFor(pass.second, perDispatch);
    gpu::DispatchRecorder recorder(context, dispatchCount);
    if (prelude.record) prelude.record(recorder);
    std::uint32_t first = 0;
    for (const auto& [name, count] : passes) {
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
        checkStackSlots(counters, push.stackSlots);
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
    checkStackSlots(counters, push.stackSlots);
}

// Secondary rays start on the surfaces, at most kOffsetSteps float32 steps of the triangles'
// coordinates off them (shaders/secondary_rays.glsl): a bound on their origins for the filter
// margin, which the host cannot take from rays it never sees.
float secondaryMargin(const Box& box) {
    glm::vec3 farthest(0.0f);
    for (int a = 0; a < 3; ++a) farthest[a] = std::max(std::abs(box.lo[a]), std::abs(box.hi[a])) * (1.0f + 0x1p-12f);
    return filterMargin(box, farthest);
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

void checkGpuOptions(const TraceOptions& options) { checkTraceOptions(options); }

GpuTracer::GpuTracer(gpu::Context& context, ThreadPool& pool, const TraceOptions& options, const GpuTuning& tuning,
                     gpu::PipelineCache* pipelines, gpu::ResidentTriangles* resident, gpu::BufferArena* arena)
    : context_(context),
      pool_(pool),
      options_(options),
      tuning_(tuning),
      limits_(gpu::bufferLimits(context.info(), tuning)),
      ownPipelines_(pipelines ? nullptr : std::make_unique<gpu::PipelineCache>(context)),
      pipelines_(pipelines ? *pipelines : *ownPipelines_),
      resident_(resident),
      arena_(arena) {
    checkGpuOptions(options);
    if (tuning.leafBalance && *tuning.leafBalance > kMostLeafBalance)
        throw InputError("a leaf balance of " + std::to_string(*tuning.leafBalance) + " is over the most the kernel takes, " +
                         std::to_string(kMostLeafBalance));
}

GpuTracer::~GpuTracer() = default;

TraceResult GpuTracer::startResult() const {
    TraceResult result;
    result.threads = pool_.size();
    describeDevice(context_.info(), result);
    return result;
}

TraceResult GpuTracer::trace(const FrameGeometry& geometry, const PlanHook& onPlan, GpuPassSourcePtr* keep) {
    const gpu::DeviceInfo& device = context_.info();
    if (!device.subgroupOperations)
        throw InputError("device '" + device.name +
                         "' lacks subgroup arithmetic or shuffles in compute shaders, which the gpu backend needs");
    Frame frame{geometry, startResult()};
    frame.rays = geometry.rays->size();
    frame.keepsTriangles = resident_ && options_.skips.uploads && geometry.trianglesVersion != 0;
    divide(frame);
    frame.workgroupSize = chooseWorkgroupSize(*frame.work, tuning_, device, frame.result);
    planMemory(frame);
    if (onPlan && !onPlan(frame.result.memory)) return std::move(frame.result);

    upload(frame);
    const bool anyHit = geometry.query == HitQuery::Any;
    compileKernel(frame, KernelRays{.sharedStart = geometry.raysShareStart,
                                    .anyHit = anyHit,
                                    .sharedSegment = anyHit && raysShareSegment(*geometry.rays)});
    dispatch(frame);
    readBack(frame);
    if (keep) {
        *keep = GpuPassSourcePtr(new GpuPassSource{});
        (*keep)->primaryRays = geometry.rays->size();
        (*keep)->primary = std::move(frame.set);
    }
    return std::move(frame.result);
}

// The same division as the cpu backend, then the work items over the region slots.
void GpuTracer::divide(Frame& frame) {
    const auto start = Clock::now();
    const gpu::DeviceInfo& device = context_.info();
    const unsigned regions = options_.regions ? options_.regions : gpu::defaultGpuRegions(device, tuning_.profile);
    const int axis = options_.axis == DivisionAxis::Best ? chooseDivisionAxis(frame.geometry, regions)
                                                         : int(options_.axis) - 1;
    frame.division = divideScene(frame.geometry, regions, axis, pool_, frame.hostPlan);
    const std::vector<TransferRound> schedule = transferSchedule(frame.division);
    const std::uint32_t groups = tuning_.rayGroups ? tuning_.rayGroups : gpu::defaultRayGroups(device, tuning_.profile, regions);
    // The discrete profile cuts the groups to equal estimated cost where the rays share an
    // origin to estimate from (estimateStep1RayCosts), else to equal ray counts.
    const std::vector<std::uint32_t> rayCosts = gpu::balancesRayGroups(device, tuning_.profile)
                                                    ? gpu::estimateStep1RayCosts(frame.geometry, frame.division, pool_)
                                                    : std::vector<std::uint32_t>{};
    frame.ownWork = gpu::planWorkItems(frame.division, schedule, groups,
                                       rayCosts.empty() ? gpu::evenRayGroups(frame.division, groups)
                                                        : gpu::costedRayGroups(frame.division, groups, rayCosts));
    frame.triIdCount = frame.work->triangleIds;
    if (gpu::kernelUsesPackets(frame.geometry, options_.dacrt, device))
        setPackets(frame, gpu::buildRayPackets(frame.geometry, frame.division.rayIds, frame.ownWork.slots, pool_));
    frame.result.regions = regions;
    frame.result.axis = axis;
    frame.result.counters.raysCulled = frame.division.culledRays;
    frame.result.gpu->rayGroups = groups;
    frame.result.phases.divide = msSince(start);
}

// The frame's packets (none: nullopt), and each work item's range of its ray slot's.
void GpuTracer::setPackets(Frame& frame, std::optional<gpu::RayPackets> packets) {
    frame.packets = std::move(packets);
    for (WorkItem& item : frame.ownWork.items) {
        item.packetBegin = frame.packets ? frame.packets->slotFirstPacket[item.rayRegion] : 0u;
        item.packetEnd = frame.packets ? frame.packets->slotFirstPacket[item.rayRegion + 1] : 0u;
    }
}

// Packets make the ray id buffer about three times as long: a frame that fits the device only
// without them is planned again without them (the same hits, more ray/box tests).
void GpuTracer::planMemory(Frame& frame) const {
    if (frame.packets) {
        const MemoryPlan before = frame.result.memory;
        try {
            planBuffers(frame);
            return;
        } catch (const InputError&) {
            frame.result.memory = before;
            setPackets(frame, std::nullopt);
        }
    }
    planBuffers(frame);
}

// Every buffer, host and device, from the counts; checked against the device's limits.
void GpuTracer::planBuffers(Frame& frame) const {
    const FrameGeometry& g = frame.geometry;
    const gpu::WorkPlan& work = *frame.work;
    frame.buffers = gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
        .rays = g.rays->size(),
        .triangles = g.triangles->size(),
        .rayIds = frame.division.rayIds.size(),
        .triangleIds = frame.triIdCount,
        .regions = work.slots.size(),
        .workItems = work.items.size(),
        .maxDepth = options_.dacrt.maxDepth,
        .stackSlots = frame.stackSlots = stackSlots(work.items.size()),
        .packets = frame.packets ? frame.packets->packets.size() : 0,
    });
    MemoryPlan& plan = frame.result.memory;
    // The frame's own arrays on the host, which the device's are uploaded from and the hits
    // read back into (the cpu backends' plans count them too; on a CPU device such as lavapipe
    // the device's copies are host memory as well).
    plan.add("host: rays", g.rays->size() * sizeof(Ray));
    plan.add("host: triangles", g.triangles->size() * sizeof(Triangle));
    plan.add("host: triangle bounds", g.triangles->size() * sizeof(Bounds));  // one per triangle
    plan.add("host: hits", g.rays->size() * sizeof(Hit));
    for (const auto& [name, bytes] : frame.hostPlan.buffers) plan.add("host: " + name, bytes);
    plan.add("host: triangle ids per ray group", frame.triIdCount * 4);
    if (frame.packets) {
        plan.add("host: packet rays", frame.packets->packetRays.size() * 4);
        plan.add("host: packets", frame.packets->packets.size() * (sizeof(PacketBounds) + 4));
        plan.add("host: ray finished flags (zeros uploaded)", g.rays->size() * 4);
    }
    gpu::addressLargeArrays(frame.buffers, limits_);
    checkStageClocks(frame.buffers);
    gpu::addToMemoryPlan(frame.buffers, limits_, plan);
    // Kept triangles in chunks this frame cannot reach (it binds what an earlier one addressed,
    // or the reverse) are uploaded again.
    frame.trianglesOnDevice = frame.keepsTriangles && resident_->holds(g, gpu::chunkBytesOf(frame.buffers));
    planBufferReuse(frame);
    plan.work.insert(plan.work.end(), frame.hostPlan.work.begin(), frame.hostPlan.work.end());
    gpu::addWorkItemLines(work, plan);
    const std::uint64_t triangleBytes = std::uint64_t(g.triangles->size()) * (sizeof(Triangle) + sizeof(Bounds));
    const std::uint64_t uploaded = std::uint64_t(g.rays->size()) * (sizeof(Ray) + sizeof(Hit)) +
                                   (frame.trianglesOnDevice ? 0 : triangleBytes) +
                                   std::uint64_t(frame.division.rayIds.size()) * 4 + frame.triIdCount * 4 +
                                   work.slots.size() * sizeof(Region) + work.items.size() *
                                   (sizeof(WorkItem) + sizeof(TraversalState)) + sizeof(GpuCounters) +
                                   (frame.packets ? (frame.packets->packetRays.size() + g.rays->size() +
                                                     frame.packets->packets.size()) * 4 +
                                                        frame.packets->packets.size() * sizeof(PacketBounds)
                                                  : 0);
    plan.addWork("bytes uploaded", uploaded, frame.packets ? "rays, misses, triangles and bounds, ids, regions, work items, packets"
                                                      : "rays, misses, triangles and bounds, ids, regions, work items");
    plan.addWork("skipped: triangle and bounds upload (bytes)", frame.trianglesOnDevice ? triangleBytes : 0,
                 frame.keepsTriangles ? (frame.trianglesOnDevice ? "on the device since an earlier frame" : "uploaded, kept for the next frame")
                                      : g.trianglesVersion ? "skip off (--no-skip uploads)" : "the triangles' version is unknown");
    plan.addWork("bytes read back", std::uint64_t(g.rays->size()) * sizeof(Hit) + work.slots.size() * sizeof(Region) +
                 work.items.size() * sizeof(TraversalState), "hits, regions and work item states (their costs)");
}

// Stage clocks read the device's subgroup clock, and only the kernel that binds every array has them.
void GpuTracer::checkStageClocks(const gpu::DacrtBufferPlan& buffers) const {
    if (!tuning_.stageClocks) return;
    const gpu::DeviceInfo& device = context_.info();
    if (!device.subgroupClock)
        throw InputError("--stage-clocks needs VK_KHR_shader_clock's shaderSubgroupClock, which device '" + device.name +
                         "' (" + device.driver + ") lacks");
    if (gpu::chunkBytesOf(buffers) != 0)
        throw InputError("--stage-clocks times the kernel that binds every array, and this frame's arrays exceed one "
                         "binding (" + limits_.bindingLimit + " of " + std::to_string(limits_.bindingBytes) +
                         " bytes); render fewer pixels to time its stages");
}

// The frame's buffers that an earlier frame left in the arena: reused, not allocated.
void GpuTracer::planBufferReuse(Frame& frame) const {
    if (!arena_) return;
    gpu::BoundElsewhere elsewhere{};
    for (std::uint32_t k = 0; k < DACRT_BINDING_COUNT; ++k) elsewhere[k] = frame.kept[k] != nullptr;
    elsewhere[DACRT_BINDING_TRIANGLES] = elsewhere[DACRT_BINDING_TRIANGLE_BOUNDS] = frame.keepsTriangles || elsewhere[DACRT_BINDING_TRIANGLES];
    frame.result.memory.addWork("device buffers reused from an earlier frame (bytes)", arena_->reusableBytes(frame.buffers, elsewhere),
                                "the rest allocated now, then kept for the next frame");
}

// Creates the frame's buffers and fills them.
void GpuTracer::upload(Frame& frame) const {
    const auto start = Clock::now();
    if (frame.keepsTriangles) {
        resident_->prepare(context_, frame.geometry, gpu::chunkBytesOf(frame.buffers));
        frame.kept[DACRT_BINDING_TRIANGLES] = &resident_->triangles();
        frame.kept[DACRT_BINDING_TRIANGLE_BOUNDS] = &resident_->bounds();
    }
    frame.set = std::make_unique<gpu::DacrtBindingSet>(context_, frame.buffers, frame.kept, arena_);
    gpu::DacrtBindingSet& set = *frame.set;
    const FrameGeometry& g = frame.geometry;
    const gpu::WorkPlan& work = *frame.work;
    const std::vector<std::uint32_t> slotTriIds = gpu::groupTriangleIds(frame.division, work.grouping);
    std::vector<Hit> misses;
    misses.reserve(g.rays->size());
    for (const Ray& ray : *g.rays) misses.push_back(missHit(ray));
    const GpuCounters zero{};
    const std::vector<TraversalState> fresh(work.items.size(), TraversalState{});
    auto upload = [&](std::uint32_t binding, const auto& v) { set[binding].upload(v.data(), v.size() * sizeof(v[0])); };
    upload(DACRT_BINDING_RAYS, *g.rays);
    if (!frame.keepsTriangles) {
        upload(DACRT_BINDING_TRIANGLES, *g.triangles);
        upload(DACRT_BINDING_TRIANGLE_BOUNDS, *g.triangleBounds);
    }
    upload(DACRT_BINDING_HITS, misses);
    upload(DACRT_BINDING_RAY_IDS, frame.division.rayIds);
    if (frame.packets) uploadPackets(frame);
    upload(DACRT_BINDING_TRI_IDS, slotTriIds);
    upload(DACRT_BINDING_REGIONS, work.slots);
    upload(DACRT_BINDING_WORK_ITEMS, work.items);
    set[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    upload(DACRT_BINDING_STATES, fresh);
    frame.result.phases.upload = msSince(start);
}

std::uint64_t GpuTracer::stackSlots(std::uint64_t workItems) const {
    return gpu::stackSlotsFor(workItems, options_.dacrt.maxDepth, context_.info(), gpu::loopBudgetOf(context_.info()) != 0);
}

void GpuTracer::compileKernel(Frame& frame, const KernelRays& rays) const {
    const auto start = Clock::now();
    const gpu::KernelLeafRule leafRule = gpu::kernelLeafRule(options_.dacrt, tuning_, context_.info());
    const std::uint32_t packetFlush = frame.packets ? options_.dacrt.resolvedFor(Backend::Gpu).packetFlush : 0u;
    gpu::ComputePipeline& pipeline = pipelines_.kernel(gpu::KernelSpecialization{
        .workgroupSize = frame.workgroupSize,
        .rayLimit = leafRule.rayLimit,
        .triLimit = leafRule.triLimit,
        .maxDepth = options_.dacrt.maxDepth,
        .loopBudget = gpu::loopBudgetOf(context_.info()),
        .sharedStart = rays.sharedStart,
        .anyHit = rays.anyHit,
        .leafOverSplit = gpu::defaultLeafOverSplit(context_.info(), tuning_.profile),
        .lockstepSubgroups = gpu::dropsBarriers(context_.info(), frame.workgroupSize),
        .leafBalance = leafRule.leafBalance,
        .packetFlush = packetFlush,
        .addressed = frame.set->addressed(),
        .chunkBytes = frame.set->kernelChunkBytes(),
        .stageClocks = tuning_.stageClocks,
        .sharedSegment = rays.sharedSegment,
        .tightBoxRays = options_.dacrt.tightBoxes ? std::uint32_t(kTightBoxRaysPerTriangle) : 0u,
    });
    frame.result.gpu->rayLimit = leafRule.rayLimit;
    frame.result.gpu->triLimit = leafRule.triLimit;
    frame.result.gpu->leafBalance = leafRule.leafBalance;
    frame.result.gpu->packets = frame.packets ? std::uint32_t(frame.packets->packets.size()) : 0u;
    frame.result.gpu->packetFlush = packetFlush;
    // Compilation only (a first use; later frames find the pipeline in the cache), so that
    // render and bench can take it out of the frame.
    PhaseTimes::addTo(frame.result.phases.pipelineCompile, msSince(start));
    frame.set->bindTo(pipeline);
    frame.kernel = &pipeline;
}

namespace {

gpu::PacketSections packetSectionsOf(const FrameGeometry& g, const Division& division, const gpu::RayPackets& packets) {
    return gpu::packetSections(division.rayIds.size(), g.rays->size(), packets.packets.size());
}

}  // namespace

// The packet sections of the ray id buffer (no ray done yet; every slot's packet ids in order)
// and the packets.
void GpuTracer::uploadPackets(Frame& frame) const {
    const gpu::RayPackets& packets = *frame.packets;
    const gpu::PacketSections at = packetSectionsOf(frame.geometry, frame.division, packets);
    gpu::Buffer& ids = (*frame.set)[DACRT_BINDING_RAY_IDS];
    ids.upload(packets.packetRays.data(), packets.packetRays.size() * 4, std::uint64_t(at.packetRays) * 4);
    const std::vector<std::uint32_t> notDone(frame.geometry.rays->size(), 0u);
    ids.upload(notDone.data(), notDone.size() * 4, std::uint64_t(at.doneFlags) * 4);
    std::vector<std::uint32_t> packetIds(packets.packets.size());
    for (std::uint32_t k = 0; k < packetIds.size(); ++k) packetIds[k] = k;
    ids.upload(packetIds.data(), packetIds.size() * 4, std::uint64_t(at.packetIds) * 4);
    (*frame.set)[DACRT_BINDING_PACKETS].upload(packets.packets.data(), packets.packets.size() * sizeof(PacketBounds));
}

// Step 1 and the transfer rounds in one command buffer, then continuations until every work
// item is done.
void GpuTracer::dispatch(Frame& frame) const {
    const auto start = Clock::now();
    DacrtPush push{};
    push.rayOrigin = frame.geometry.nearSide;  // the shared origin when raysShareStart
    push.margin = frame.geometry.margin;
    push.axis = std::uint32_t(frame.division.axis);
    push.rayScratchHalf = std::uint32_t(frame.division.rayIds.size());
    push.triScratchHalf = std::uint32_t(frame.triIdCount);
    push.loopProbe = 2;
    push.rayTmin = frame.geometry.rays->front().tmin;
    push.rayTmax = frame.geometry.rays->front().tmax;  // every ray's where compileKernel found them shared
    push.order = frame.geometry.order == ChildOrder::PerRay ? shared::kOrderPerRay : shared::kOrderNearSide;
    push.stackSlots = std::uint32_t(frame.stackSlots);
    if (frame.packets) {
        const gpu::PacketSections at = packetSectionsOf(frame.geometry, frame.division, *frame.packets);
        push.rayScratchHalf = std::uint32_t(at.scratch);
        push.packetRaysAt = std::uint32_t(at.packetRays);
        push.doneFlagsAt = std::uint32_t(at.doneFlags);
        push.packetIdsAt = std::uint32_t(at.packetIds);
        push.packetCount = std::uint32_t(frame.packets->packets.size());
    }
    frame.counters = dispatchSchedule(*frame.work, context_, *frame.kernel, *frame.set, push, *frame.result.gpu);
    dispatchContinuations(*frame.work, context_, *frame.kernel, *frame.set, push, frame.counters, *frame.result.gpu);
    frame.result.phases.dispatch = msSince(start);
}

void GpuTracer::readBack(Frame& frame) const {
    const auto start = Clock::now();
    TraceResult& result = frame.result;
    const gpu::WorkPlan& work = *frame.work;
    const gpu::DacrtBindingSet& set = *frame.set;
    result.hits.resize(frame.rays);
    set[DACRT_BINDING_HITS].download(result.hits.data(), result.hits.size() * sizeof(Hit));
    std::vector<Region> after(work.slots.size());
    set[DACRT_BINDING_REGIONS].download(after.data(), after.size() * sizeof(Region));
    std::vector<TraversalState> states(work.items.size());
    set[DACRT_BINDING_STATES].download(states.data(), states.size() * sizeof(TraversalState));
    result.phases.readback = msSince(start);

    const GpuCounters& counters = frame.counters;
    checkLoopLimit(counters, work.items.size(), context_.info());
    result.counters.raysCulled += counters.raysCulled;  // a secondary pass's (the division counted a frame's)
    result.counters.rayBoxTests = counters.rayBoxTests;
    result.counters.packetBoxTests = counters.packetBoxTests;
    result.counters.tightBoxes = counters.tightBoxes;
    result.counters.rayTriangleTests = counters.rayTriangleTests;
    result.counters.leaves = counters.leaves;
    result.counters.raysFinishedWithoutHit = counters.raysRetired;
    result.counters.finishedStep1 = counters.terminatedStep1;
    result.counters.transferWorkItems = work.transferPairs;
    GpuReport& report = *result.gpu;
    report.raysFinished = 0;  // one command buffer: no per-round readback
    for (const Region& r : after) report.raysFinished += r.terminated - r.rayBegin;
    report.dispatches = std::uint32_t(report.dispatchMs.size());
    report.slices = counters.slices;
    report.workItemsRun = counters.workItemsRun;
    report.workItemsEmpty = counters.workItemsEmpty;
    report.validationErrors = context_.validationErrors();
    std::vector<std::uint32_t> costs;
    costs.reserve(states.size());
    for (const TraversalState& state : states) costs.push_back(state.cost);
    gpu::reportWorkSpread(work, costs, report);
    if (tuning_.stageClocks) report.stageTicks = gpu::stageTicksOf(counters);
}

TraceResult GpuTracer::traceSecondary(GpuPassSource& source, const FrameGeometry& geometry, const SecondaryPass& pass,
                                      const PlanHook& onPlan) {
    Frame frame{geometry, startResult()};
    if (!source.divided) divideForSecondaryRays(source, geometry, frame.result);
    frame.rays = secondarySlots(pass, source.primaryRays);
    frame.work = &source.work;
    frame.triIdCount = source.work.triangleIds;
    frame.result.regions = unsigned(source.division.regions.size());
    frame.result.axis = source.division.axis;
    frame.result.gpu->rayGroups = source.work.groups;

    // Ray counts per slot are the device's to find: the estimate for the workgroup size is an
    // even share.
    gpu::WorkPlan sizing = source.work;
    sizing.largestSlotRays = std::uint32_t(std::min<std::uint64_t>(frame.rays / std::max<std::size_t>(sizing.slots.size(), 1),
                                                                   std::numeric_limits<std::uint32_t>::max()));
    frame.workgroupSize = chooseWorkgroupSize(sizing, tuning_, context_.info(), frame.result);
    planPass(frame, source, pass);
    if (onPlan && !onPlan(frame.result.memory)) return std::move(frame.result);

    uploadPass(frame, source);
    compileKernel(frame, KernelRays{.anyHit = true, .sharedSegment = true});  // secondary_rays.glsl's segments
    const auto start = Clock::now();
    frame.rayMaker = &pipelines_.secondary(frame.set->addressed(), frame.set->kernelChunkBytes());
    frame.set->bindTo(*frame.rayMaker);
    PhaseTimes::addTo(frame.result.phases.pipelineCompile, msSince(start));
    dispatchPass(frame, source, pass);
    readBack(frame);
    return std::move(frame.result);
}

// The first secondary pass of a frame divides its triangles (rays: none yet) and plans work
// items for every pair of regions, since rays of every direction may move between any two.
void GpuTracer::divideForSecondaryRays(GpuPassSource& source, const FrameGeometry& frame, TraceResult& result) const {
    const auto start = Clock::now();
    const gpu::DeviceInfo& device = context_.info();
    const unsigned regions = options_.regions ? options_.regions : gpu::defaultGpuRegions(device, tuning_.profile);
    const glm::vec3 extent = frame.sceneBox.extent();
    const int longest = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const int axis = options_.axis == DivisionAxis::Best ? longest : int(options_.axis) - 1;
    static const std::vector<Ray> noRays;
    FrameGeometry triangles = frame;
    triangles.rays = &noRays;
    triangles.tracedTriangles = nullptr;
    // The margin the kernel and the device's ray binning filter with: triangles straddle by it.
    source.margin = secondaryMargin(frame.sceneBox);
    triangles.margin = source.margin;
    MemoryPlan unused;
    source.division = divideScene(triangles, regions, axis, pool_, unused);
    const std::uint32_t groups = tuning_.rayGroups ? tuning_.rayGroups : gpu::defaultRayGroups(device, tuning_.profile, regions);
    // The device bins the rays by slot, region k's group g in slot k * groups + g
    // (shaders/secondary.comp): every region has the same groups.
    source.work = gpu::planWorkItems(source.division, transferSchedule(source.division, false), groups,
                                     gpu::evenRayGroups(source.division, groups));
    const std::vector<std::uint32_t> ids = gpu::groupTriangleIds(source.division, source.work.grouping);
    // Beyond one binding, in the chunks that the passes then address (planPass); on a device
    // without buffer device addresses the buffer (or the pass's plan) names the limit.
    const std::uint64_t idBytes = std::max<std::uint64_t>(ids.size(), 1) * 8;
    const bool chunked = idBytes > limits_.bindingBytes && limits_.addresses;
    source.triangleIds = std::make_unique<gpu::Buffer>(context_, idBytes, "triangle ids and scratch (secondary passes)",
                                                       gpu::BufferUse::Storage, chunked ? limits_.chunkBytes : 0);
    source.triangleIds->upload(ids.data(), ids.size() * sizeof(std::uint32_t));
    source.divided = true;
    result.phases.divide = msSince(start);
}

// The pass's buffers from its slot count; those it shares with the primary pass counted once,
// as kept.
void GpuTracer::planPass(Frame& frame, const GpuPassSource& source, const SecondaryPass& pass) const {
    frame.buffers = gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
        .rays = frame.rays,
        .triangles = frame.geometry.triangles->size(),
        .rayIds = frame.rays,
        .triangleIds = frame.triIdCount,
        .regions = source.work.slots.size(),
        .workItems = source.work.items.size(),
        .maxDepth = options_.dacrt.maxDepth,
        .stackSlots = frame.stackSlots = stackSlots(source.work.items.size()),
        .sourceRays = source.primaryRays,
    });
    gpu::DacrtBindingSet& primary = *source.primary;
    frame.kept[DACRT_BINDING_TRIANGLES] = &primary[DACRT_BINDING_TRIANGLES];
    frame.kept[DACRT_BINDING_TRIANGLE_BOUNDS] = &primary[DACRT_BINDING_TRIANGLE_BOUNDS];
    frame.kept[DACRT_BINDING_TRI_IDS] = source.triangleIds.get();
    frame.kept[DACRT_BINDING_SOURCE_RAYS] = &primary[DACRT_BINDING_RAYS];
    frame.kept[DACRT_BINDING_SOURCE_HITS] = &primary[DACRT_BINDING_HITS];
    gpu::addressLargeArrays(frame.buffers, limits_);
    std::uint64_t kept = source.triangleIds->size(), keptUnbound = 0;
    for (std::uint32_t k = 0; k < DACRT_BINDING_COUNT; ++k) {
        kept += primary[k].size();
        const bool bound = std::find(frame.kept.begin(), frame.kept.end(), &primary[k]) != frame.kept.end();
        if (!bound) keptUnbound += primary[k].size();
    }
    MemoryPlan& plan = frame.result.memory;
    gpu::addToMemoryPlan(frame.buffers, limits_, plan, &frame.kept, keptUnbound);
    plan.add("device: kept from the primary pass (its rays, hits, triangles and work buffers)", kept);
    planBufferReuse(frame);
    plan.addWork("rays made on the device", frame.rays,
                 std::to_string(pass.raysPerHit) + " per primary hit, where the surface can send one");
    gpu::addWorkItemLines(source.work, plan);
}

void GpuTracer::uploadPass(Frame& frame, const GpuPassSource& source) const {
    const auto start = Clock::now();
    frame.set = std::make_unique<gpu::DacrtBindingSet>(context_, frame.buffers, frame.kept, arena_);
    gpu::DacrtBindingSet& set = *frame.set;
    const GpuCounters zero{};
    const std::vector<TraversalState> fresh(source.work.items.size(), TraversalState{});
    set[DACRT_BINDING_REGIONS].upload(source.work.slots.data(), source.work.slots.size() * sizeof(Region));
    set[DACRT_BINDING_WORK_ITEMS].upload(source.work.items.data(), source.work.items.size() * sizeof(WorkItem));
    set[DACRT_BINDING_STATES].upload(fresh.data(), fresh.size() * sizeof(TraversalState));
    set[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    frame.result.phases.upload = msSince(start);
}

// The rays made on the device ahead of Step 1, in the same command buffer, then the rounds
// and continuations as a primary frame's.
void GpuTracer::dispatchPass(Frame& frame, const GpuPassSource& source, const SecondaryPass& pass) const {
    const auto start = Clock::now();
    DacrtPush push{};
    push.margin = source.margin;
    push.axis = std::uint32_t(source.division.axis);
    push.rayScratchHalf = std::uint32_t(frame.rays);
    push.triScratchHalf = std::uint32_t(frame.triIdCount);
    push.loopProbe = 2;
    push.order = shared::kOrderPerRay;  // any hit: every ray visits the low child, then the high
    push.rayTmin = shared::kSegmentStart;
    push.rayTmax = passSegmentEnd(pass);
    push.stackSlots = std::uint32_t(frame.stackSlots);
    const Prelude prelude = makeRaysOnDevice(*frame.rayMaker, secondaryPush(source, pass), frame.rays,
                                             context_.info().maxComputeWorkGroupCountX);
    frame.counters = dispatchSchedule(source.work, context_, *frame.kernel, *frame.set, push, *frame.result.gpu, prelude);
    dispatchContinuations(source.work, context_, *frame.kernel, *frame.set, push, frame.counters, *frame.result.gpu);
    frame.result.phases.dispatch = msSince(start);
}

}  // namespace dacrt
