#include "library/api_results.hpp"

#include "cpu/phase_times.hpp"

namespace dacrt {

static_assert(kNoPrimitive == kMissPrim && kUnnamedPrimitive == kUnnamedHitPrim,
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
    return timings;
}

TraceCounters countersOf(const TraceResult& result) {
    TraceCounters c;
    c.rayBoxTests = result.counters.rayBoxTests;
    c.packetBoxTests = result.counters.packetBoxTests;
    c.rayTriangleTests = result.counters.rayTriangleTests;
    c.leaves = result.counters.leaves;
    c.raysCulled = result.counters.raysCulled;
    c.threads = result.threads;
    c.regions = result.regions;
    if (result.gpu) c.device = result.gpu->device;
    return c;
}

std::vector<RayHit> hitsOf(const std::vector<Hit>& hits, const std::vector<std::uint32_t>& callerIds) {
    std::vector<RayHit> out;
    out.reserve(hits.size());
    for (const Hit& h : hits) {
        const bool named = h.prim != kMissPrim && h.prim != kUnnamedHitPrim;
        out.push_back(RayHit{named && !callerIds.empty() ? callerIds[h.prim] : h.prim, h.t, h.u, h.v});
    }
    return out;
}

}  // namespace

FramePlan framePlanOf(const MemoryPlan& plan) {
    FramePlan out;
    for (const auto& [name, bytes] : plan.buffers) out.memory.push_back({name, bytes});
    for (const WorkLine& w : plan.work) out.work.push_back({w.name, w.count, w.why});
    return out;
}

TraceOutput traceOutputOf(const TraceResult& result, const std::vector<std::uint32_t>& callerIds, double totalMs) {
    TraceOutput out;
    out.hits = hitsOf(result.hits, callerIds);
    out.timings = timingsOf(result.phases, totalMs);
    out.counters = countersOf(result);
    out.plan = framePlanOf(result.memory);
    return out;
}

}  // namespace dacrt
