#include "gpu/work_plan.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/errors.hpp"

namespace dacrt::gpu {

std::vector<Region> groupRegions(const Division& division, std::uint32_t groups) {
    if (std::uint64_t(division.triIds.size()) * groups > std::numeric_limits<std::uint32_t>::max())
        throw InputError(std::to_string(division.triIds.size()) + " triangle ids times " + std::to_string(groups) +
                         " ray groups exceed the kernel's 32-bit ids; use fewer ray groups");
    std::vector<Region> slots;
    std::uint32_t triNext = 0;
    for (std::size_t k = 0; k < division.regions.size(); ++k) {
        const Region& r = division.regions[k];
        const std::uint32_t rays = r.rayEnd - r.rayBegin;
        for (std::uint32_t g = 0; g < groups; ++g) {
            Region slot = r;
            slot.directions = (division.raysTowardLow[k] ? shared::kTowardLow : 0u) | (division.raysTowardHigh[k] ? shared::kTowardHigh : 0u);
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

WorkPlan planWorkItems(const Division& division, const std::vector<TransferRound>& schedule, std::uint32_t groups) {
    WorkPlan plan;
    plan.groups = groups;
    plan.slots = groupRegions(division, groups);
    const std::uint32_t slots = std::uint32_t(plan.slots.size());
    std::vector<std::uint32_t> rayUses(slots, 0), triUses(slots, 0);
    auto addItem = [&](std::uint32_t rayRegion, std::uint32_t triRegion, std::uint32_t retire) {
        for (std::uint32_t g = 0; g < groups; ++g) {
            const std::uint32_t raySlot = rayRegion * groups + g, triSlot = triRegion * groups + g;
            plan.items.push_back(WorkItem{raySlot, triSlot, retire, rayUses[raySlot]++, triUses[triSlot]++, 0, 0, 0});
        }
    };
    const std::uint32_t regions = std::uint32_t(division.regions.size());
    for (std::uint32_t k = 0; k < regions; ++k) addItem(k, k, 0);
    plan.passes.emplace_back("step1", slots);
    for (const TransferRound& round : schedule) {
        // Retire codes as the kernel reads them: 1 rays moving up, 2 moving down.
        for (const TransferPair& p : round.pairs) addItem(p.rayRegion, p.triRegion, p.triRegion > p.rayRegion ? 1u : 2u);
        plan.passes.emplace_back(round.name, std::uint32_t(round.pairs.size()) * groups);
        plan.transferPairs += std::uint32_t(round.pairs.size());
    }
    for (const Region& r : plan.slots) {
        plan.largestSlotRays = std::max(plan.largestSlotRays, r.rayEnd - r.rayBegin);
        plan.largestSlotTriangles = std::max(plan.largestSlotTriangles, r.triEnd - r.triBegin);
    }
    return plan;
}

}  // namespace dacrt::gpu
