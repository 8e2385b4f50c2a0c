#include "gpu/work_spread.hpp"

#include <algorithm>

namespace dacrt::gpu {

std::uint64_t longestChainCost(const WorkPlan& work, const std::vector<std::uint32_t>& costs) {
    // Items are in schedule order and wait for all earlier items on their slots, so the latest
    // finish on a slot is the one an item waits for.
    std::vector<std::uint64_t> rayFinish(work.slots.size(), 0), triFinish(work.slots.size(), 0);
    std::uint64_t longest = 0;
    for (std::size_t i = 0; i < work.items.size(); ++i) {
        const WorkItem& item = work.items[i];
        const std::uint64_t finish = std::max(rayFinish[item.rayRegion], triFinish[item.triRegion]) + costs[i];
        rayFinish[item.rayRegion] = triFinish[item.triRegion] = finish;
        longest = std::max(longest, finish);
    }
    return longest;
}

void addWorkItemLines(const WorkPlan& work, MemoryPlan& plan) {
    plan.addWork("gpu work items", work.items.size(), "Step 1 and transfer pairs, per ray group");
    const std::vector<std::pair<std::string, std::uint32_t>> dispatches = dispatchedPasses(work);
    for (std::size_t p = 0; p < dispatches.size(); ++p)
        plan.addWork("gpu work items: " + dispatches[p].first, dispatches[p].second,
                     p == 0 ? "one dispatch, independent of each other"
                            : "one dispatch, each after the earlier items on its ray and triangle slots");
    plan.addWork("gpu longest chain of work items", longestChainCost(work, std::vector<std::uint32_t>(work.items.size(), 1)),
                 "work items that wait for each other, in a row");
}

void reportWorkSpread(const WorkPlan& work, const std::vector<std::uint32_t>& costs, GpuReport& report) {
    report.workPasses.clear();
    report.workCost = 0;
    std::size_t first = 0;
    for (const auto& [name, count] : dispatchedPasses(work)) {
        GpuWorkPass pass{name, count, 0, 0.0};
        std::uint64_t sum = 0;
        for (std::size_t i = first; i < first + count; ++i) {
            pass.maxCost = std::max<std::uint64_t>(pass.maxCost, costs[i]);
            sum += costs[i];
        }
        pass.meanCost = count ? double(sum) / count : 0.0;
        report.workCost += sum;
        report.workPasses.push_back(pass);
        first += count;
    }
    report.longestChainCost = longestChainCost(work, costs);
}

}  // namespace dacrt::gpu
