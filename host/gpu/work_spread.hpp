#pragma once
// How a frame's work items share out the kernel's work: the work items of each dispatch
// (Step 1, then each transfer round), the spread of their costs, and the parallelism the
// schedule offers (docs/gpu.md, "Work items and parallelism").
#include <cstdint>
#include <vector>

#include "cpu/memory_plan.hpp"
#include "cpu/trace_result.hpp"
#include "gpu/work_plan.hpp"

namespace dacrt::gpu {

// The costliest chain of work items that wait for each other, given each item's cost (in
// schedule order): a work item waits for every earlier one on its ray slot and on its triangle
// slot (raySeq, triSeq), so Step 1's items are independent and a round's item follows the
// latest items on its two slots. With every cost 1 it is the longest chain in work items.
std::uint64_t longestChainCost(const WorkPlan& work, const std::vector<std::uint32_t>& costs);

// What --plan can say before tracing: the work items of each dispatch and the longest chain
// counted in work items.
void addWorkItemLines(const WorkPlan& work, MemoryPlan& plan);

// The measured spread: each dispatch's work items with their largest and mean cost (the loop
// iterations of the kernel's cost model, TraversalState::cost), the total and the longest
// chain, into the report.
void reportWorkSpread(const WorkPlan& work, const std::vector<std::uint32_t>& costs, GpuReport& report);

}  // namespace dacrt::gpu
