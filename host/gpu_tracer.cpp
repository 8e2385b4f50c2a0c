#include "gpu_tracer.hpp"

#include <chrono>

#include "dacrt_traversal.hpp"
#include "errors.hpp"
#include "scene_division.hpp"
#include "vk_resources.hpp"

#include "dacrt.spv.h"

namespace dacrt {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

std::uint32_t defaultWorkgroupSize(const vk::DeviceInfo& device) {
    const std::uint32_t subgroup = std::max(device.subgroupSize, 1u);
    const std::uint32_t wanted = device.type == "cpu" ? subgroup : std::max(64u, subgroup);
    return std::min(wanted, device.maxComputeWorkGroupInvocations);
}

TraceResult traceGpu(const FrameGeometry& g, const TraceOptions& options, const GpuTuning& tuning,
                     vk::Context& context, ThreadPool& pool, const PlanHook& onPlan) {
    const vk::DeviceInfo& device = context.info();
    if (options.dacrt.split != SplitMethod::SpatialMedian)
        throw InputError("--split " + toString(options.dacrt.split) + " is not available on the gpu backend (spatial-median only)");
    if (!device.subgroupArithmetic)
        throw InputError("device '" + device.name + "' lacks subgroup arithmetic in compute shaders, which the gpu backend needs");
    const std::uint32_t workgroupSize = tuning.workgroupSize ? tuning.workgroupSize : defaultWorkgroupSize(device);
    if (workgroupSize > device.maxComputeWorkGroupInvocations || workgroupSize > device.maxComputeWorkGroupSizeX)
        throw InputError("--workgroup-size " + std::to_string(workgroupSize) + " exceeds the device limit of " +
                         std::to_string(std::min(device.maxComputeWorkGroupInvocations, device.maxComputeWorkGroupSizeX)));

    TraceResult result;
    result.gpu = GpuReport{};
    GpuReport& report = *result.gpu;
    report.device = device.name;
    report.driver = device.driver;
    report.workgroupSize = workgroupSize;
    report.subgroupSize = device.subgroupSize;
    const unsigned regions = options.regions ? options.regions : 64;
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

    std::vector<WorkItem> items;
    for (std::uint32_t k = 0; k < regions; ++k) items.push_back(WorkItem{k, k, 0, 0});
    for (const TransferRound& round : schedule)
        for (const TransferPair& p : round.pairs)
            items.push_back(WorkItem{p.rayRegion, p.triRegion, p.triRegion > p.rayRegion ? 1u : 2u, 0});
    result.phaseMs.emplace_back("divide", msSince(start));

    // Every device buffer, sized from the counts before anything is allocated on the device.
    const std::uint64_t rayCount = g.rays->size(), triCount = g.triangles->size();
    const std::uint64_t rayIdCount = division.rayIds.size(), triIdCount = division.triIds.size();
    struct Planned {
        const char* name;
        std::uint64_t bytes;
    };
    const std::vector<Planned> deviceBuffers = {
        {"device: rays", rayCount * sizeof(Ray)},
        {"device: triangles", triCount * sizeof(Triangle)},
        {"device: triangle bounds", triCount * sizeof(Bounds)},
        {"device: hits", rayCount * sizeof(Hit)},
        {"device: ray ids", rayIdCount * 4},
        {"device: triangle ids", triIdCount * 4},
        {"device: ray scratch", rayIdCount * 8},
        {"device: triangle scratch", triIdCount * 8},
        {"device: regions", std::uint64_t(regions) * sizeof(Region)},
        {"device: work items", items.size() * sizeof(WorkItem)},
        {"device: counters", sizeof(GpuCounters)},
    };
    for (const auto& [name, bytes] : hostPlan.buffers) result.memory.add("host: " + name, bytes);
    for (const Planned& b : deviceBuffers) {
        result.memory.add(b.name, b.bytes);
        if (b.bytes > device.maxStorageBufferRange)
            throw InputError(std::string(b.name + 8) + " needs " + std::to_string(b.bytes) + " bytes, more than the " +
                             "device's maxStorageBufferRange of " + std::to_string(device.maxStorageBufferRange) +
                             " bytes (over by " + std::to_string(b.bytes - device.maxStorageBufferRange) +
                             "); render at a smaller --size or split the scene");
    }
    if (onPlan && !onPlan(result.memory)) return result;

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
    buffers[DACRT_BINDING_TRI_IDS].upload(division.triIds.data(), triIdCount * 4);
    buffers[DACRT_BINDING_REGIONS].upload(division.regions.data(), regions * sizeof(Region));
    buffers[DACRT_BINDING_WORK_ITEMS].upload(items.data(), items.size() * sizeof(WorkItem));
    const GpuCounters zero{};
    buffers[DACRT_BINDING_COUNTERS].upload(&zero, sizeof(zero));
    result.phaseMs.emplace_back("upload", msSince(start));

    start = Clock::now();
    vk::ComputePipeline pipeline(context, std::span<const std::uint32_t>(dacrt_spv, sizeof(dacrt_spv) / 4),
                                 DACRT_BINDING_COUNT, sizeof(DacrtPush),
                                 {workgroupSize, options.dacrt.rayLimit, options.dacrt.triLimit, options.dacrt.maxDepth},
                                 "dacrt");
    std::vector<const vk::Buffer*> bound;
    for (const vk::Buffer& b : buffers) bound.push_back(&b);
    pipeline.bind(bound);
    result.phaseMs.emplace_back("pipeline", msSince(start));

    start = Clock::now();
    vk::DispatchRecorder recorder(context, std::uint32_t(1 + schedule.size()));
    DacrtPush push{};
    push.rayOrigin = g.rayOrigin;
    push.margin = g.margin;
    push.axis = std::uint32_t(axis);
    push.rayScratchHalf = std::uint32_t(rayIdCount);
    push.triScratchHalf = std::uint32_t(triIdCount);
    push.firstWorkItem = 0;
    push.loopProbe = 2;
    recorder.dispatch("step1", pipeline, regions, &push);
    push.firstWorkItem = regions;
    for (const TransferRound& round : schedule) {
        recorder.dispatch(round.name, pipeline, std::uint32_t(round.pairs.size()), &push);
        push.firstWorkItem += std::uint32_t(round.pairs.size());
    }
    recorder.submitAndWait();
    result.phaseMs.emplace_back("dispatch", msSince(start));

    start = Clock::now();
    result.hits.resize(rayCount);
    buffers[DACRT_BINDING_HITS].download(result.hits.data(), rayCount * sizeof(Hit));
    GpuCounters counters{};
    buffers[DACRT_BINDING_COUNTERS].download(&counters, sizeof(counters));
    std::vector<Region> after(regions);
    buffers[DACRT_BINDING_REGIONS].download(after.data(), regions * sizeof(Region));
    result.phaseMs.emplace_back("readback", msSince(start));

    if (counters.loopLimitHits > 0)
        throw InputError(std::to_string(counters.loopLimitHits) + " of " + std::to_string(items.size()) +
                         " work items were cut short by the driver's loop limit (" + device.driver +
                         " ends every shader invocation after 65535 loop iterations in all): each work item is " +
                         "too large at " + std::to_string(regions) + " regions; use more --regions or a larger " +
                         "--workgroup-size (docs/gpu.md)");
    result.counters.rayBoxTests = counters.rayBoxTests;
    result.counters.rayTriangleTests = counters.rayTriangleTests;
    result.counters.leaves = counters.leaves;
    result.counters.raysRetired = counters.raysRetired;
    std::uint64_t finished = 0;
    for (const Region& r : after) finished += r.terminated - r.rayBegin;
    result.counters.terminatedStep1 = finished;  // the gpu reports all rays finished, not per round
    result.counters.transferWorkItems = items.size() - regions;
    report.dispatchMs = recorder.timingsMs();
    report.dispatches = recorder.dispatchCount();
    report.workItemsRun = counters.workItemsRun;
    report.workItemsEmpty = counters.workItemsEmpty;
    report.validationErrors = context.validationErrors();
    return result;
}

}  // namespace dacrt
