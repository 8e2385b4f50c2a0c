#pragma once
// A backend's TraceResult as the public API reports it (include/dacrt/results.hpp): the one
// place where internal hits, phases, counters and plans become public types.
#include <cstdint>
#include <vector>

#include <dacrt/results.hpp>

#include "cpu/memory_plan.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

class ThreadPool;

// callerIds: the caller's id of each traced triangle (TraceScene::Impl); empty: the same ids.
// totalMs: the whole call, measured around the trace. Throws InternalError on a phase that
// TraceTimings has no field for. pool: the hits converted in chunks side by side (none: on
// the calling thread).
TraceOutput traceOutputOf(const TraceResult& result, const std::vector<std::uint32_t>& callerIds, double totalMs,
                          ThreadPool* pool = nullptr);

FramePlan framePlanOf(const MemoryPlan& plan);
MemoryPlan memoryPlanOf(const FramePlan& plan);

}  // namespace dacrt
