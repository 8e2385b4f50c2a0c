#pragma once
// The gpu backend's work items: the parallel scheme's Step 1 and transfer rounds over
// region slots (regions split into ray groups), in schedule order.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/shader_layout.hpp"
#include "cpu/scene_division.hpp"

namespace dacrt::gpu {

// Ray groups: each region's rays split into `groups` consecutive runs (rays are in pixel
// order, so these are bands of the image), each with its own copy of the region's triangle
// ids, so that the groups of a region are separate work items that run at once and finish
// at different times, which evens out the load of the workgroups. Region k's group g is
// slot k * groups + g; the ray ids are unchanged. groupRegions gives the slots' table
// (InputError if the triangle ids would overflow 32 bits), groupTriangleIds the copies in
// slot order; they are apart so that the plan is checked before the copies are made.
std::vector<Region> groupRegions(const Division& division, std::uint32_t groups);
std::vector<std::uint32_t> groupTriangleIds(const Division& division, std::uint32_t groups);

struct WorkPlan {
    std::uint32_t groups = 1;
    std::vector<Region> slots;              // groupRegions
    std::vector<WorkItem> items;            // Step 1, then each round, in schedule order
    // Step 1 and each transfer round: name and work item count, in order.
    std::vector<std::pair<std::string, std::uint32_t>> passes;
    std::uint32_t largestSlotRays = 0;
    std::uint32_t largestSlotTriangles = 0;
    std::uint32_t transferPairs = 0;        // as the cpu backend counts them
};

// raySeq and triSeq of each work item count the earlier work items on the same ray and
// triangle slots, which the kernel waits for.
WorkPlan planWorkItems(const Division& division, const std::vector<TransferRound>& schedule, std::uint32_t groups);

}  // namespace dacrt::gpu
