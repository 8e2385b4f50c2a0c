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

// Ray groups: each region's rays split into consecutive runs (rays are in pixel order, so
// these are bands of the image), each with its own copy of the region's triangle ids, so that
// the groups of a region are separate work items that run at once and finish at different
// times, which evens out the load of the workgroups. Region k's groups are the slots
// firstSlot[k] to firstSlot[k + 1] - 1; slot s's rays begin at rayStart[s], an index into
// division.rayIds, and end where the next slot of the region begins, or at the region's end.
// The ray ids are unchanged.
struct RayGroups {
    std::vector<std::uint32_t> firstSlot;  // one per region, and the slot count
    std::vector<std::uint32_t> rayStart;   // one per slot
    std::uint32_t groupsOf(std::size_t region) const { return firstSlot[region + 1] - firstSlot[region]; }
};

// `groups` groups of equal ray counts in every region.
RayGroups evenRayGroups(const Division& division, std::uint32_t groups);

// As many groups as evenRayGroups, shared out by estimated cost (rayCosts: one per entry of
// division.rayIds, gpu/ray_cost_estimate.hpp; each ray weighs kRayBaseWeight plus its
// estimate): each next group goes to the region whose groups weigh most, as long as the
// triangle id copies stay within evenRayGroups' (no more memory); within a region the groups
// are cut to equal weights, so that a band of rays that pass near many of the region's
// triangles holds fewer rays than one that passes beside them.
inline constexpr std::uint32_t kRayBaseWeight = 2;
RayGroups costedRayGroups(const Division& division, std::uint32_t groups, const std::vector<std::uint32_t>& rayCosts);

// groupRegions gives the slots' table (InputError if the triangle ids would overflow 32 bits),
// groupTriangleIds the copies in slot order; they are apart so that the plan is checked before
// the copies are made.
std::vector<Region> groupRegions(const Division& division, const RayGroups& groups);
std::vector<std::uint32_t> groupTriangleIds(const Division& division, const RayGroups& groups);

struct WorkPlan {
    std::uint32_t groups = 1;               // the groups asked for (evenRayGroups: every region's)
    RayGroups grouping;
    std::vector<Region> slots;              // groupRegions
    std::vector<WorkItem> items;            // Step 1, then each round, in schedule order
    // Step 1 and each transfer round: name and work item count, in order.
    std::vector<std::pair<std::string, std::uint32_t>> passes;
    std::uint64_t triangleIds = 0;          // over every slot's copy
    std::uint32_t largestSlotRays = 0;
    std::uint32_t largestSlotTriangles = 0;
    std::uint32_t transferPairs = 0;        // as the cpu backend counts them
};

// raySeq and triSeq of each work item count the earlier work items on the same ray and
// triangle slots, which the kernel waits for. A transfer pair's work item on ray group g of
// region A uses copy g mod n of region B's triangles (B having n groups): where A has more
// groups than B, several of its work items share a copy, one after another.
WorkPlan planWorkItems(const Division& division, const std::vector<TransferRound>& schedule, std::uint32_t groups,
                       const RayGroups& grouping);

// The plan's passes as dispatches: consecutive passes whose work items use no ray slot and no
// triangle slot in common run as one dispatch ("toward-low 1 + toward-high 1"), since none of
// them waits for another; apart, each would keep the device to its own few work items (with
// two regions, a transfer round is one work item: one of a CPU device's threads).
std::vector<std::pair<std::string, std::uint32_t>> dispatchedPasses(const WorkPlan& plan);

}  // namespace dacrt::gpu
