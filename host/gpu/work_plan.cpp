#include "gpu/work_plan.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <queue>

#include "core/errors.hpp"

namespace dacrt::gpu {

namespace {

std::uint64_t rayWeight(std::uint32_t cost) { return kRayBaseWeight + std::uint64_t(cost); }

std::uint64_t trianglesOf(const Region& r) { return r.triEnd - r.triBegin; }

// One group per region, then one at a time to the region whose groups weigh most, while its
// next copy of triangle ids fits in what `groups` copies of every region would take and leaves
// room for the groups still to share out (in the region with the fewest triangles that has rays),
// so that every group asked for is given.
std::vector<std::uint32_t> shareOutGroups(const Division& division, std::uint32_t groups, const std::vector<std::uint64_t>& weights) {
    const std::size_t regions = division.regions.size();
    std::vector<std::uint32_t> counts(regions, 1);
    std::uint64_t idsLeft = std::uint64_t(division.triIds.size()) * (groups - 1);
    std::uint64_t groupsLeft = std::uint64_t(regions) * (groups - 1);
    // weights[a] / counts[a] < weights[b] / counts[b], without rounding.
    auto lighter = [&](std::size_t a, std::size_t b) { return weights[a] * counts[b] < weights[b] * counts[a]; };
    std::priority_queue<std::size_t, std::vector<std::size_t>, decltype(lighter)> heaviest(lighter);
    std::uint64_t fewestIds = std::numeric_limits<std::uint64_t>::max();
    for (std::size_t k = 0; k < regions; ++k)
        if (weights[k] > 0) {
            heaviest.push(k);
            fewestIds = std::min(fewestIds, trianglesOf(division.regions[k]));
        }
    while (groupsLeft > 0 && !heaviest.empty()) {
        const std::size_t k = heaviest.top();
        heaviest.pop();
        const std::uint64_t ids = trianglesOf(division.regions[k]);
        if (ids + (groupsLeft - 1) * fewestIds > idsLeft) continue;  // it keeps its groups
        ++counts[k];
        idsLeft -= ids;
        --groupsLeft;
        heaviest.push(k);
    }
    return counts;
}

// The region's rays cut into `count` runs of equal weight: each run begins after the first ray
// whose running sum reaches its share of the total.
void cutToEqualWeights(const Region& r, std::uint32_t count, const std::vector<std::uint32_t>& rayCosts, std::uint64_t total,
                       std::vector<std::uint32_t>& rayStart) {
    rayStart.push_back(r.rayBegin);
    std::uint64_t sum = 0;
    std::uint32_t g = 1;  // the next group to begin
    for (std::uint32_t i = r.rayBegin; i < r.rayEnd && g < count; ++i) {
        sum += rayWeight(rayCosts[i]);
        for (; g < count && sum * count >= total * g; ++g) rayStart.push_back(i + 1);
    }
    for (; g < count; ++g) rayStart.push_back(r.rayEnd);
}

}  // namespace

RayGroups evenRayGroups(const Division& division, std::uint32_t groups) {
    RayGroups grouping;
    for (const Region& r : division.regions) {
        grouping.firstSlot.push_back(std::uint32_t(grouping.rayStart.size()));
        for (std::uint32_t g = 0; g < groups; ++g)
            grouping.rayStart.push_back(r.rayBegin + std::uint32_t(std::uint64_t(r.rayEnd - r.rayBegin) * g / groups));
    }
    grouping.firstSlot.push_back(std::uint32_t(grouping.rayStart.size()));
    return grouping;
}

RayGroups costedRayGroups(const Division& division, std::uint32_t groups, const std::vector<std::uint32_t>& rayCosts) {
    std::vector<std::uint64_t> weights;
    for (const Region& r : division.regions) {
        std::uint64_t total = 0;
        for (std::uint32_t i = r.rayBegin; i < r.rayEnd; ++i) total += rayWeight(rayCosts[i]);
        weights.push_back(total);
    }
    const std::vector<std::uint32_t> counts = shareOutGroups(division, groups, weights);
    RayGroups grouping;
    for (std::size_t k = 0; k < division.regions.size(); ++k) {
        grouping.firstSlot.push_back(std::uint32_t(grouping.rayStart.size()));
        cutToEqualWeights(division.regions[k], counts[k], rayCosts, weights[k], grouping.rayStart);
    }
    grouping.firstSlot.push_back(std::uint32_t(grouping.rayStart.size()));
    return grouping;
}

std::vector<Region> groupRegions(const Division& division, const RayGroups& groups) {
    std::uint64_t ids = 0;
    for (std::size_t k = 0; k < division.regions.size(); ++k) ids += trianglesOf(division.regions[k]) * groups.groupsOf(k);
    if (ids > std::numeric_limits<std::uint32_t>::max())
        throw InputError(std::to_string(ids) + " triangle ids over " + std::to_string(groups.rayStart.size()) +
                         " ray groups exceed the kernel's 32-bit ids; use fewer ray groups");
    std::vector<Region> slots;
    std::uint32_t triNext = 0;
    for (std::size_t k = 0; k < division.regions.size(); ++k) {
        const Region& r = division.regions[k];
        const std::uint32_t first = groups.firstSlot[k], count = groups.groupsOf(k);
        for (std::uint32_t g = 0; g < count; ++g) {
            Region slot = r;
            slot.directions = (division.raysTowardLow[k] ? shared::kTowardLow : 0u) | (division.raysTowardHigh[k] ? shared::kTowardHigh : 0u);
            slot.rayBegin = groups.rayStart[first + g];
            slot.rayEnd = g + 1 < count ? groups.rayStart[first + g + 1] : r.rayEnd;
            slot.terminated = slot.rayBegin;
            slot.triBegin = triNext;
            triNext += r.triEnd - r.triBegin;
            slot.triEnd = triNext;
            slots.push_back(slot);
        }
    }
    return slots;
}

std::vector<std::uint32_t> groupTriangleIds(const Division& division, const RayGroups& groups) {
    std::vector<std::uint32_t> ids;
    for (std::size_t k = 0; k < division.regions.size(); ++k) {
        const Region& r = division.regions[k];
        for (std::uint32_t g = 0; g < groups.groupsOf(k); ++g)
            ids.insert(ids.end(), division.triIds.begin() + r.triBegin, division.triIds.begin() + r.triEnd);
    }
    return ids;
}

WorkPlan planWorkItems(const Division& division, const std::vector<TransferRound>& schedule, std::uint32_t groups,
                       const RayGroups& grouping) {
    WorkPlan plan;
    plan.groups = groups;
    plan.grouping = grouping;
    plan.slots = groupRegions(division, grouping);
    const std::uint32_t slots = std::uint32_t(plan.slots.size());
    std::vector<std::uint32_t> rayUses(slots, 0), triUses(slots, 0);
    auto addItems = [&](std::uint32_t rayRegion, std::uint32_t triRegion, std::uint32_t retire) {
        const std::uint32_t rayGroups = grouping.groupsOf(rayRegion), triCopies = grouping.groupsOf(triRegion);
        for (std::uint32_t g = 0; g < rayGroups; ++g) {
            const std::uint32_t raySlot = grouping.firstSlot[rayRegion] + g, triSlot = grouping.firstSlot[triRegion] + g % triCopies;
            plan.items.push_back(WorkItem{raySlot, triSlot, retire, rayUses[raySlot]++, triUses[triSlot]++, 0, 0, 0});
        }
        return rayGroups;
    };
    const std::uint32_t regions = std::uint32_t(division.regions.size());
    for (std::uint32_t k = 0; k < regions; ++k) addItems(k, k, 0);
    plan.passes.emplace_back("step1", slots);
    for (const TransferRound& round : schedule) {
        std::uint32_t items = 0;
        // Retire codes as the kernel reads them: 1 rays moving up, 2 moving down.
        for (const TransferPair& p : round.pairs) items += addItems(p.rayRegion, p.triRegion, p.triRegion > p.rayRegion ? 1u : 2u);
        plan.passes.emplace_back(round.name, items);
        plan.transferPairs += std::uint32_t(round.pairs.size());
    }
    for (const Region& r : plan.slots) {
        plan.largestSlotRays = std::max(plan.largestSlotRays, r.rayEnd - r.rayBegin);
        plan.largestSlotTriangles = std::max(plan.largestSlotTriangles, r.triEnd - r.triBegin);
        plan.triangleIds += r.triEnd - r.triBegin;
    }
    return plan;
}

std::vector<std::pair<std::string, std::uint32_t>> dispatchedPasses(const WorkPlan& plan) {
    std::vector<std::pair<std::string, std::uint32_t>> merged;
    std::vector<bool> raySlotUsed(plan.slots.size(), false), triSlotUsed(plan.slots.size(), false);
    std::uint32_t first = 0;
    for (const auto& [name, count] : plan.passes) {
        const auto items = plan.items.begin() + first;
        const bool disjoint = !merged.empty() && std::none_of(items, items + count, [&](const WorkItem& w) {
            return raySlotUsed[w.rayRegion] || triSlotUsed[w.triRegion];
        });
        if (!disjoint) {
            merged.emplace_back(name, count);
            std::fill(raySlotUsed.begin(), raySlotUsed.end(), false);
            std::fill(triSlotUsed.begin(), triSlotUsed.end(), false);
        } else {
            merged.back().first += " + " + name;
            merged.back().second += count;
        }
        for (auto w = items; w != items + count; ++w) raySlotUsed[w->rayRegion] = triSlotUsed[w->triRegion] = true;
        first += count;
    }
    return merged;
}

}  // namespace dacrt::gpu
