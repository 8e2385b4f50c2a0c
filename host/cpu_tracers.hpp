#pragma once
// The CPU backends: brute force, sequential DACRT, and the parallel scheme.
#include <functional>

#include "thread_pool.hpp"
#include "trace_types.hpp"

namespace dacrt {

// Called with the complete memory plan after the counting passes and before the id arrays
// are allocated or anything is traced. Returning false stops the frame there: the result
// then holds the plan and no hits. It may also throw (a plan that does not fit).
using PlanHook = std::function<bool(const MemoryPlan&)>;

// Every ray against every triangle (threads split the rays).
TraceResult traceBrute(const FrameGeometry& geometry, ThreadPool& pool, const PlanHook& onPlan = {});

// One DACRT over the whole scene on the calling thread.
TraceResult traceSequential(const FrameGeometry& geometry, const DacrtOptions& options, const PlanHook& onPlan = {});

// The parallel scheme: division into regions, Step 1 (one DACRT per region), then the
// transfer rounds; work items of a step run on the pool.
TraceResult traceParallel(const FrameGeometry& geometry, const TraceOptions& options, ThreadPool& pool,
                          const PlanHook& onPlan = {});

TraceResult traceCpu(const FrameGeometry& geometry, const TraceOptions& options, ThreadPool& pool,
                     const PlanHook& onPlan = {});

}  // namespace dacrt
