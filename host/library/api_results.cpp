#include "library/api_results.hpp"

#include <string_view>
#include <utility>

#include <dacrt/errors.hpp>

#include "gpu/gpu_tracer.hpp"

namespace dacrt {

static_assert(kNoPrimitive == kMissPrim && kUnnamedPrimitive == kUnnamedHitPrim,
              "the public primitive ids are the kernels' own");

namespace {

// Each phase name the backends report (TraceResult::phaseMs) and its field.
constexpr std::pair<std::string_view, double TraceTimings::*> kPhaseFields[] = {
    {"skips", &TraceTimings::skipsMs},
    {"divide", &TraceTimings::divideMs},
    {"step1", &TraceTimings::step1Ms},
    {"transfer", &TraceTimings::transferMs},
    {"build", &TraceTimings::buildMs},
    {"refit", &TraceTimings::buildMs},
    {"allocate", &TraceTimings::allocateMs},
    {"upload", &TraceTimings::uploadMs},
    {kPipelinePhase, &TraceTimings::pipelineCompileMs},
    {"dispatch", &TraceTimings::dispatchMs},
    {"readback", &TraceTimings::readbackMs},
    {"trace", &TraceTimings::traceMs},
};

TraceTimings timingsOf(const std::vector<std::pair<std::string, double>>& phaseMs, double totalMs) {
    TraceTimings timings;
    timings.totalMs = totalMs;
    for (const auto& [name, ms] : phaseMs) {
        bool known = false;
        for (const auto& [phase, field] : kPhaseFields)
            if (name == phase) {
                timings.*field += ms;
                known = true;
                break;
            }
        if (!known) throw InternalError("trace phase '" + name + "' has no field in dacrt::TraceTimings");
    }
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
    out.timings = timingsOf(result.phaseMs, totalMs);
    out.counters = countersOf(result);
    out.plan = framePlanOf(result.memory);
    return out;
}

}  // namespace dacrt
