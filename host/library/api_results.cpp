#include "library/api_results.hpp"

#include <dacrt/plan_text.hpp>

#include "core/mapped_memory.hpp"
#include "core/thread_pool.hpp"
#include "cpu/phase_times.hpp"
#include "gpu/stage_clocks.hpp"

namespace dacrt {

static_assert(kNoPrimitive == kMissPrim && kUnnamedPrimitive == kUnnamedHitPrim && kNotTracedPrimitive == kNotTracedPrim,
              "the public primitive ids are the kernels' own");

namespace {

TraceTimings timingsOf(const PhaseTimes& phases, double totalMs) {
    TraceTimings timings;
    timings.totalMs = totalMs;
    timings.skipsMs = phases.skips.value_or(0.0);
    timings.divideMs = phases.divide.value_or(0.0);
    timings.step1Ms = phases.step1.value_or(0.0);
    timings.transferMs = phases.transfer.value_or(0.0);
    timings.buildMs = phases.structureMs();
    timings.allocateMs = phases.allocate.value_or(0.0);
    timings.uploadMs = phases.upload.value_or(0.0);
    timings.pipelineCompileMs = phases.compileMs();
    timings.dispatchMs = phases.dispatch.value_or(0.0);
    timings.readbackMs = phases.readback.value_or(0.0);
    timings.traceMs = phases.trace.value_or(0.0);
    for (const auto& [name, ms] : phases.listed()) timings.phases.push_back({name, ms});
    return timings;
}

TraceCounters countersOf(const TraceResult& result) {
    TraceCounters c;
    c.rayBoxTests = result.counters.rayBoxTests;
    c.packetBoxTests = result.counters.packetBoxTests;
    c.rayTriangleTests = result.counters.rayTriangleTests;
    c.rayTriangleTestsSkipped = result.counters.rayTriangleTestsSkipped;
    c.leaves = result.counters.leaves;
    c.tightBoxes = result.counters.tightBoxes;
    c.raysCulled = result.counters.raysCulled;
    c.raysFinishedWithoutHit = result.counters.raysFinishedWithoutHit;
    c.raysFinishedStep1 = result.counters.finishedStep1;
    for (std::size_t i = 0; i < result.counters.finishedPerRound.size(); ++i)
        c.transferRounds.push_back({result.counters.roundNames[i], result.counters.finishedPerRound[i]});
    c.transferWorkItems = result.counters.transferWorkItems;
    c.transferWorkItemsSkipped = result.counters.transferWorkItemsSkipped;
    c.threads = result.threads;
    c.regions = result.regions;
    c.divisionAxis = result.axis;
    if (result.gpu) c.device = result.gpu->device;
    return c;
}

std::vector<RayHit> hitsOf(const std::vector<Hit>& hits, const std::vector<std::uint32_t>& callerIds, ThreadPool* pool) {
    std::vector<RayHit> out;
    resizeMapped(out, hits.size());
    forEachChunk(hits.size(), kFrameScanChunk, pool, [&](std::size_t, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            const Hit& h = hits[i];
            const bool named = h.prim != kMissPrim && h.prim != kUnnamedHitPrim && h.prim != kNotTracedPrim;
            out[i] = RayHit{named && !callerIds.empty() ? callerIds[h.prim] : h.prim, h.t, h.u, h.v};
        }
    });
    return out;
}

DeviceReport deviceReportOf(const GpuReport& g) {
    std::vector<DeviceReport::Dispatch> dispatchTimes;
    for (const auto& [name, ms] : g.dispatchMs) dispatchTimes.push_back({name, ms});
    std::vector<DeviceReport::WorkPass> workPasses;
    for (const GpuWorkPass& p : g.workPasses) workPasses.push_back({p.name, p.items, p.maxCost, p.meanCost});
    std::vector<DeviceReport::StageTicks> stageTicks;
    for (std::size_t k = 0; k < g.stageTicks.size(); ++k) stageTicks.push_back({gpu::stageName(k), g.stageTicks[k]});
    return DeviceReport{.device = g.device, .driver = g.driver, .workgroupSize = g.workgroupSize,
                        .subgroupSize = g.subgroupSize, .rayGroups = g.rayGroups,
                        .rayLimit = g.rayLimit, .triLimit = g.triLimit, .leafBalance = g.leafBalance,
                        .packets = g.packets, .packetFlush = g.packetFlush,
                        .dispatchTimes = std::move(dispatchTimes), .dispatches = g.dispatches,
                        .workItemsRun = g.workItemsRun, .workItemsEmpty = g.workItemsEmpty, .workItemSlices = g.slices,
                        .raysFinished = g.raysFinished, .validationErrors = g.validationErrors,
                        .workPasses = std::move(workPasses), .workCost = g.workCost, .longestChainCost = g.longestChainCost,
                        .stageTicks = std::move(stageTicks)};
}

}  // namespace

MemoryPlan memoryPlanOf(const FramePlan& plan) {
    MemoryPlan out;
    for (const FramePlan::Buffer& b : plan.memory) out.add(b.name, b.bytes);
    for (const FramePlan::Work& w : plan.work) out.addWork(w.name, w.count, w.why);
    return out;
}

std::string describeMemory(const FramePlan& plan) { return memoryPlanOf(plan).describe(); }
std::string describeWork(const FramePlan& plan) { return memoryPlanOf(plan).describeWork(); }

FramePlan framePlanOf(const MemoryPlan& plan) {
    FramePlan out;
    for (const auto& [name, bytes] : plan.buffers) out.memory.push_back({name, bytes});
    for (const WorkLine& w : plan.work) out.work.push_back({w.name, w.count, w.why});
    return out;
}

TraceOutput traceOutputOf(const TraceResult& result, const std::vector<std::uint32_t>& callerIds, double totalMs,
                          ThreadPool* pool) {
    TraceOutput out;
    out.hits = hitsOf(result.hits, callerIds, pool);
    out.timings = timingsOf(result.phases, totalMs);
    out.counters = countersOf(result);
    out.plan = framePlanOf(result.memory);
    out.timings.step1RegionMs = result.step1RegionMs;
    if (result.gpu) out.gpu = deviceReportOf(*result.gpu);
    return out;
}

}  // namespace dacrt
