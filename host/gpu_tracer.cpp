#include "gpu_tracer.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <thread>

#include "dacrt_traversal.hpp"
#include "errors.hpp"
#include "scene_division.hpp"
#include "timing.hpp"
#include "vk_resources.hpp"

#include "dacrt.spv.h"

namespace dacrt {

std::uint32_t loopBudgetOf(const vk::DeviceInfo& device) {
    // llvmpipe stops all loops of an invocation after 65535 iterations in all; keep a margin
    // for the few loops the kernel's cost estimates round down.
    return device.driver.find("llvmpipe") != std::string::npos ? 40000u : 0u;
}

namespace {

// The widest workgroup the kernel takes: the device's limits, and at most as many subgroups
// as one subgroup has lanes (workgroupExclusiveSum sums the subgroup totals in one subgroup).
std::uint32_t widestWorkgroup(const vk::DeviceInfo& device) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    return std::min({device.maxComputeWorkGroupInvocations, device.maxComputeWorkGroupSizeX, subgroup * subgroup});
}

}  // namespace

std::uint32_t defaultWorkgroupSize(const vk::DeviceInfo& device, std::uint32_t largestRegionRays,
                                   std::uint32_t largestRegionTriangles) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = widestWorkgroup(device);
    std::uint32_t size = device.type == "cpu" ? subgroup : std::max(64u, subgroup);
    if (const std::uint32_t budget = loopBudgetOf(device)) {
        // The largest single step (a split of the biggest region, then its final partition)
        // must fit one slice: about (2 (rays + triangles) + 2 rays) / (4 size) iterations, a
        // partition step taking four ids per invocation (kIdsPerInvocation).
        const double needed = (4.0 * largestRegionRays + 2.0 * largestRegionTriangles) / (4.0 * 0.8 * budget);
        while (size < widest && double(size) < needed) size *= 2;
    }
    return std::min(size, widest);
}

vk::ComputePipeline& PipelineCache::get(const std::vector<std::uint32_t>& specialization) {
    std::unique_ptr<vk::ComputePipeline>& slot = pipelines_[specialization];
    if (!slot)
        slot = std::make_unique<vk::ComputePipeline>(context_, std::span<const std::uint32_t>(dacrt_spv, sizeof(dacrt_spv) / 4),
                                                     DACRT_BINDING_COUNT, sizeof(DacrtPush), specialization, "dacrt");
    return *slot;
}

std::vector<Region> groupRegions(const Division& division, std::uint32_t groups) {
    if (std::uint64_t(division.triIds.size()) * groups > std::numeric_limits<std::uint32_t>::max())
        throw InputError(std::to_string(division.triIds.size()) + " triangle ids times " + std::to_string(groups) +
                         " ray groups exceed the kernel's 32-bit ids; use fewer --ray-groups");
    std::vector<Region> slots;
    std::uint32_t triNext = 0;
    for (const Region& r : division.regions) {
        const std::uint32_t rays = r.rayEnd - r.rayBegin;
        for (std::uint32_t g = 0; g < groups; ++g) {
            Region slot = r;
            slot.rayBegin = r.rayBegin + std::uint32_t(std::uint64_t(rays) * g / groups);
            slot.rayEnd = r.rayBegin + std::uint32_t(std::uint64_t(rays) * (g + 1) / groups);
            slot.terminated = slot.rayBegin;
            slot.triBegin = triNext;
            triNext += r.triEnd - r.triBegin;
            slot.triEnd = triNext;
            slots.push_back(slot);
        }
    }
    return slots;
}

std::vector<std::uint32_t> groupTriangleIds(const Division& division, std::uint32_t groups) {
    std::vector<std::uint32_t> ids;
    ids.reserve(division.triIds.size() * groups);
    for (const Region& r : division.regions)
        for (std::uint32_t g = 0; g < groups; ++g)
            ids.insert(ids.end(), division.triIds.begin() + r.triBegin, division.triIds.begin() + r.triEnd);
    return ids;
}

bool raysShareStart(const std::vector<Ray>& rays) {
    // Bitwise, so that the kernel's arithmetic on the shared values is the per-ray one.
    return std::all_of(rays.begin(), rays.end(), [&](const Ray& r) {
        return std::memcmp(&r.origin, &rays.front().origin, sizeof(r.origin)) == 0 &&
               std::memcmp(&r.tmin, &rays.front().tmin, sizeof(r.tmin)) == 0;
    });
}

std::uint32_t defaultRayGroups(const vk::DeviceInfo& device, unsigned regions) {
    // A CPU device: two per region, so that a thread whose work item ends early finds
    // another (docs/gpu.md). A GPU: at least 64 work items in Step 1 (unmeasured).
    return device.type == "cpu" ? 2u : std::max(1u, (64u + regions - 1u) / regions);
}

unsigned defaultGpuRegions(const vk::DeviceInfo& device) {
    // A CPU device runs one workgroup per thread: one region per core, as for the cpu backend,
    // measured best on lavapipe (docs/benchmarks.md: 2 regions beat 16 by 35% on the Bunny
    // and 17% on the Dragon). A GPU wants many work items; 16 is unmeasured there.
    return device.type == "cpu" ? std::max(1u, std::thread::hardware_concurrency()) : 16u;
}

TraceResult traceGpu(const FrameGeometry& g, const TraceOptions& options, const GpuTuning& tuning,
                     vk::Context& context, ThreadPool& pool, const PlanHook& onPlan, PipelineCache* pipelines) {
    const vk::DeviceInfo& device = context.info();
    if (options.dacrt.split != SplitMethod::SpatialMedian)
        throw InputError("--split " + toString(options.dacrt.split) + " is not available on the gpu backend (spatial-median only)");
    if (!options.dacrt.exactDefaults())
        throw InputError("--intersector " + toString(options.dacrt.intersector) + ", --triangle-filter " +
                         toString(options.dacrt.triangleFilter) + ", --precision " + toString(options.dacrt.precision) +
                         ": the gpu backend runs only the defaults (watertight, bounds, f32); the others are cpu and "
                         "cpu-seq options");
    if (!device.subgroupOperations)
        throw InputError("device '" + device.name + "' lacks subgroup arithmetic or shuffles in compute shaders, which the gpu backend needs");
    const std::uint32_t loopBudget = loopBudgetOf(device);
    const bool sharedStart = raysShareStart(*g.rays);
    const DacrtOptions leafLimits = options.dacrt.resolvedFor(Backend::Gpu);

    TraceResult result;
    result.gpu = GpuReport{};
    GpuReport& report = *result.gpu;
    report.device = device.name;
    report.driver = device.driver;
    report.subgroupSize = device.subgroupSize;
    const unsigned regions = options.regions ? options.regions : defaultGpuRegions(device);
    result.regions = regions;
    result.threads = pool.size();

    // Division on the host: the same code as the cpu backend.
    auto start = Clock::now();
    const int axis = options.axis == DivisionAxis::Best ? chooseDivisionAxis(g, regions) : int(options.axis) - 1;
    result.axis = axis;
    MemoryPlan hostPlan;
    Division division = divideScene(g, regions, axis, pool, hostPlan);
    const std::vector<TransferRound> schedule = transferSchedule(division);
    result.counters.raysCulled = division.culledRays;

    const std::uint32_t groups = tuning.rayGroups ? tuning.rayGroups : defaultRayGroups(device, regions);
    report.rayGroups = groups;
    const std::vector<Region> slotRegions = groupRegions(division, groups);

    // Work items in schedule order; raySeq and triSeq count the earlier users of each range.
    const std::uint32_t slots = std::uint32_t(slotRegions.size());
    std::vector<WorkItem> items;
    std::vector<std::uint32_t> rayUses(slots, 0), triUses(slots, 0);
    auto addItem = [&](std::uint32_t rayRegion, std::uint32_t triRegion, std::uint32_t retire) {
        for (std::uint32_t g = 0; g < groups; ++g) {
            const std::uint32_t raySlot = rayRegion * groups + g, triSlot = triRegion * groups + g;
            items.push_back(WorkItem{raySlot, triSlot, retire, rayUses[raySlot]++, triUses[triSlot]++, 0, 0, 0});
        }
    };
    for (std::uint32_t k = 0; k < regions; ++k) addItem(k, k, 0);
    for (const TransferRound& round : schedule)
        for (const TransferPair& p : round.pairs) addItem(p.rayRegion, p.triRegion, p.triRegion > p.rayRegion ? 1u : 2u);
    std::uint32_t largestRays = 0, largestTris = 0;
    for (const Region& r : slotRegions) {
        largestRays = std::max(largestRays, r.rayEnd - r.rayBegin);
        largestTris = std::max(largestTris, r.triEnd - r.triBegin);
    }
    result.phaseMs.emplace_back("divide", msSince(start));

    const std::uint32_t workgroupSize =
        tuning.workgroupSize ? tuning.workgroupSize : defaultWorkgroupSize(device, largestRays, largestTris);
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t widest = widestWorkgroup(device);
    if (workgroupSize % subgroup != 0 || workgroupSize > widest)
        throw InputError("--workgroup-size " + std::to_string(workgroupSize) + " must be a multiple of the subgroup size " +
                         std::to_string(subgroup) + " and at most " + std::to_string(widest) + " on this device");
    report.workgroupSize = workgroupSize;

    // Every device buffer, sized from the counts before anything is allocated on the device.
    const std::uint64_t rayCount = g.rays->size(), triCount = g.triangles->size();
    const std::uint64_t rayIdCount = division.rayIds.size(), triIdCount = std::uint64_t(division.triIds.size()) * groups;
    struct Planned {
        const char* name;
        std::uint64_t bytes;
    };
    const std::vector<Planned> deviceBuffers = {
        {"device: rays", rayCount * sizeof(Ray)},
        {"device: triangles", triCount * sizeof(Triangle)},
        {"device: triangle bounds", triCount * sizeof(Bounds)},
        {"device: hits", rayCount * sizeof(Hit)},
        {"device: ray ids and scratch", rayIdCount * 8},
        {"device: triangle ids and scratch", triIdCount * 8},
        {"device: regions", std::uint64_t(slots) * sizeof(Region)},
        {"device: work items", items.size() * sizeof(WorkItem)},
        {"device: counters", sizeof(GpuCounters)},
        {"device: traversal states", items.size() * sizeof(TraversalState)},
        {"device: traversal stacks", items.size() * (options.dacrt.maxDepth + 1) * sizeof(StackEntry)},
    };
    for (const auto& [name, bytes] : hostPlan.buffers) result.memory.add("host: " + name, bytes);
    result.memory.add("host: triangle ids per ray group", triIdCount * 4);
    for (const Planned& b : deviceBuffers) {
        result.memory.add(b.name, b.bytes);
        if (b.bytes > device.maxStorageBufferRange)
            throw InputError(std::string(b.name + 8) + " needs " + std::to_string(b.bytes) + " bytes, more than the " +
                             "device's maxStorageBufferRange of " + std::to_string(device.maxStorageBufferRange) +
                             " bytes (over by " + std::to_string(b.bytes - device.maxStorageBufferRange) +
                             "); render at a smaller --size or split the scene");
    }
    if (onPlan && !onPlan(result.memory)) return result;
    const std::vector<std::uint32_t> slotTriIds = groupTriangleIds(division, groups);

    start = Clock::now();
    auto buffer = [&](const Planned& p) { return vk::Buffer(context, p.bytes, p.name); };
    std::vector<vk::Buffer> buffers;
    buffers.reserve(deviceBuffers.size());
    for (const Planned& p : deviceBuffers) buffers.push_back(buffer(p));
    std::vector<Hit> hits(rayCount, missHit());
    buffers[DACRT_BINDING_RAYS].upload(g.rays->data(), rayCount * sizeof(Ray));
    buffers[DACRT_BINDING_TRIANGLES].upload(g.triangles->data(), triCount * sizeof(Triangle));
    buffers[DACRT_BINDING_TRIANGLE_BOUNDS].upload(g.triangleBounds->data(), triCount * sizeof(Bounds));
    buffers[DACRT_BINDING_HITS].upload(hits.data(), rayCount * sizeof(Hit));
    buffers[DACRT_BINDING_RAY_IDS].upload(division.rayIds.data(), rayIdCount * 4);
    buffers[DACRT_BINDING_TRI_IDS].upload(slotTriIds.data(), triIdCount * 4);
    buffers[DACRT_BINDING_REGIONS].upload(slotRegions.data(), slots * sizeof(Region));
    buffers[DACRT_BINDING_WORK_ITEMS].upload(items.data(), items.size() * sizeof(WorkItem));
    const GpuCounters zero{};
    buffers[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    const std::vector<TraversalState> fresh(items.size(), TraversalState{});
    buffers[DACRT_BINDING_STATES].upload(fresh.data(), fresh.size() * sizeof(TraversalState));
    result.phaseMs.emplace_back("upload", msSince(start));

    start = Clock::now();
    PipelineCache frameOnly(context);
    vk::ComputePipeline& pipeline = (pipelines ? *pipelines : frameOnly)
                                        .get({workgroupSize, leafLimits.rayLimit, leafLimits.triLimit,
                                              options.dacrt.maxDepth, loopBudget, sharedStart ? 1u : 0u});
    std::vector<const vk::Buffer*> bound;
    for (const vk::Buffer& b : buffers) bound.push_back(&b);
    pipeline.bind(bound);
    result.phaseMs.emplace_back("pipeline", msSince(start));

    // One command buffer: Step 1, then each transfer round, one dispatch each. A work item
    // that runs out of loop budget (llvmpipe) is finished by continuation dispatches over all
    // work items, submitted until every one is done.
    start = Clock::now();
    DacrtPush push{};
    push.rayOrigin = g.rayOrigin;
    push.margin = g.margin;
    push.axis = std::uint32_t(axis);
    push.rayScratchHalf = std::uint32_t(rayIdCount);
    push.triScratchHalf = std::uint32_t(triIdCount);
    push.loopProbe = 2;
    push.rayTmin = g.rays->front().tmin;
    GpuCounters counters{};
    const std::uint32_t perDispatch = device.maxComputeWorkGroupCountX;
    {
        // Step 1, then each round; a pass with more work items than one dispatch may hold
        // takes several.
        std::vector<std::pair<std::string, std::uint32_t>> passes = {{"step1", slots}};
        for (const TransferRound& round : schedule) passes.emplace_back(round.name, std::uint32_t(round.pairs.size()) * groups);
        std::uint32_t dispatchCount = 0;
        for (const auto& pass : passes) dispatchCount += (pass.second + perDispatch - 1) / perDispatch;
        vk::DispatchRecorder recorder(context, dispatchCount);
        std::uint32_t first = 0;
        for (const auto& [name, count] : passes) {
            for (std::uint32_t done = 0; done < count; done += perDispatch) {
                push.firstWorkItem = first + done;
                recorder.dispatch(name, pipeline, std::min(perDispatch, count - done), &push);
            }
            first += count;
        }
        recorder.submitAndWait();
        for (const auto& t : recorder.timingsMs()) report.dispatchMs.push_back(t);
        buffers[DACRT_BINDING_COUNTERS].download(&counters, sizeof(counters));
    }
    // A slice cut short by the loop limiter has left its work item in an unknown state, so it
    // is checked first, after every submission.
    auto checkLoopLimit = [&] {
        if (counters.loopLimitHits > 0)
            throw InputError(std::to_string(counters.loopLimitHits) + " of " + std::to_string(items.size()) +
                             " work item slices were cut short by the driver's loop limit (" + device.driver +
                             " ends every shader invocation after 65535 loop iterations in all); the kernel's cost " +
                             "estimates undercount this scene: please report it (docs/gpu.md)");
    };
    constexpr std::uint32_t kContinuationsPerSubmit = 8;
    while (counters.itemsFinished < items.size()) {
        checkLoopLimit();
        if (counters.tooLarge > 0)
            throw InputError(std::to_string(counters.tooLarge) + " work items have a single step larger than the loop "
                             "budget of " + std::to_string(loopBudget) + " iterations (" + device.driver +
                             "); use a larger --workgroup-size or more --regions (docs/gpu.md)");
        const std::uint32_t slicesBefore = counters.slices;
        const std::uint32_t dispatchesPerPass = std::uint32_t((items.size() + perDispatch - 1) / perDispatch);
        vk::DispatchRecorder recorder(context, kContinuationsPerSubmit * dispatchesPerPass);
        for (std::uint32_t c = 0; c < kContinuationsPerSubmit; ++c)
            for (std::uint32_t first = 0; first < items.size(); first += perDispatch) {
                push.firstWorkItem = first;
                recorder.dispatch("continuation", pipeline, std::min<std::uint32_t>(perDispatch, std::uint32_t(items.size()) - first),
                                  &push);
            }
        recorder.submitAndWait();
        for (const auto& t : recorder.timingsMs()) report.dispatchMs.push_back(t);
        buffers[DACRT_BINDING_COUNTERS].download(&counters, sizeof(counters));
        if (counters.slices == slicesBefore)
            throw std::logic_error("gpu work items stopped making progress (" + std::to_string(counters.itemsFinished) +
                                   " of " + std::to_string(items.size()) + " finished)");
    }
    result.phaseMs.emplace_back("dispatch", msSince(start));

    start = Clock::now();
    result.hits.resize(rayCount);
    buffers[DACRT_BINDING_HITS].download(result.hits.data(), rayCount * sizeof(Hit));
    std::vector<Region> after(slots);
    buffers[DACRT_BINDING_REGIONS].download(after.data(), slots * sizeof(Region));
    result.phaseMs.emplace_back("readback", msSince(start));

    checkLoopLimit();
    result.counters.rayBoxTests = counters.rayBoxTests;
    result.counters.rayTriangleTests = counters.rayTriangleTests;
    result.counters.leaves = counters.leaves;
    result.counters.raysRetired = counters.raysRetired;
    std::uint64_t finished = 0;
    for (const Region& r : after) finished += r.terminated - r.rayBegin;
    report.raysFinished = finished;  // one command buffer: no per-round readback
    result.counters.transferWorkItems = (items.size() - slots) / groups;  // pairs, as on the cpu backend
    report.dispatches = std::uint32_t(report.dispatchMs.size());
    report.slices = counters.slices;
    report.workItemsRun = counters.workItemsRun;
    report.workItemsEmpty = counters.workItemsEmpty;
    report.validationErrors = context.validationErrors();
    return result;
}

}  // namespace dacrt
