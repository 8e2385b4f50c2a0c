// The gpu backend's ray groups and work items, on the host: how Step 1's groups are cut (equal
// ray counts, or shared out by estimated cost), that every ray and transfer pair is covered, and
// the estimate they are cut by.
#include <algorithm>

#include <gtest/gtest.h>

#include "core/procedural.hpp"
#include "core/thread_pool.hpp"
#include "gpu/ray_cost_estimate.hpp"
#include "gpu/work_plan.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

Scene twoShapes() {
    return sceneFromMeshes({icosphere({-0.5f, 0.0f, 0.0f}, 0.6f, 3), box({0.2f, -0.5f, -0.5f}, {0.9f, 0.5f, 0.4f})});
}

// Every region's groups tile its rays in order, each slot with its own copy of its region's
// triangle ids.
void expectGroupsTileTheRegions(const Division& d, const gpu::RayGroups& groups) {
    const std::vector<Region> slots = gpu::groupRegions(d, groups);
    const std::vector<std::uint32_t> triIds = gpu::groupTriangleIds(d, groups);
    ASSERT_EQ(groups.firstSlot.size(), d.regions.size() + 1);
    ASSERT_EQ(slots.size(), groups.firstSlot.back());
    for (std::size_t k = 0; k < d.regions.size(); ++k) {
        const Region& region = d.regions[k];
        ASSERT_GE(groups.groupsOf(k), 1u);
        std::uint32_t next = region.rayBegin;
        for (std::uint32_t s = groups.firstSlot[k]; s < groups.firstSlot[k + 1]; ++s) {
            const Region& slot = slots[s];
            EXPECT_EQ(slot.rayBegin, next);
            EXPECT_LE(slot.rayBegin, slot.rayEnd);
            EXPECT_EQ(slot.terminated, slot.rayBegin);
            next = slot.rayEnd;
            EXPECT_EQ(slot.lo, region.lo);
            EXPECT_EQ(slot.hi, region.hi);
            EXPECT_TRUE(std::equal(triIds.begin() + slot.triBegin, triIds.begin() + slot.triEnd,
                                   d.triIds.begin() + region.triBegin, d.triIds.begin() + region.triEnd));
        }
        EXPECT_EQ(next, region.rayEnd);
    }
}

struct DividedFrame {
    Frame frame{twoShapes(), defaultCamera(twoShapes(), 48, 36), 48, 36};
    ThreadPool pool{1};
    Division division;
    explicit DividedFrame(unsigned regions) {
        MemoryPlan plan;
        division = divideScene(frame.geometry, regions, 0, pool, plan);
    }
};

}  // namespace

TEST(WorkPlan, EvenGroupsSplitEachRegionsRaysAndCopyItsTriangles) {
    const DividedFrame f(3);
    for (std::uint32_t groups : {1u, 2u, 7u, 500u}) {
        const gpu::RayGroups grouping = gpu::evenRayGroups(f.division, groups);
        expectGroupsTileTheRegions(f.division, grouping);
        for (std::size_t k = 0; k < f.division.regions.size(); ++k) {
            const Region& r = f.division.regions[k];
            EXPECT_EQ(grouping.groupsOf(k), groups);
            for (std::uint32_t s = grouping.firstSlot[k]; s < grouping.firstSlot[k + 1]; ++s) {
                const std::uint32_t end = s + 1 < grouping.firstSlot[k + 1] ? grouping.rayStart[s + 1] : r.rayEnd;
                EXPECT_LE(end - grouping.rayStart[s], (r.rayEnd - r.rayBegin + groups - 1) / groups);
            }
        }
        EXPECT_EQ(gpu::groupTriangleIds(f.division, grouping).size(), f.division.triIds.size() * groups);
    }
}

TEST(WorkPlan, CostedGroupsFollowTheEstimateWithinTheSameMemory) {
    const DividedFrame f(4);
    const Division& d = f.division;
    // Region 1's rays cost 40 each, the others' nothing: region 1 gets the most groups.
    std::vector<std::uint32_t> costs(d.rayIds.size(), 0);
    const Region& costly = d.regions[1];
    ASSERT_GT(costly.rayEnd - costly.rayBegin, 100u);
    std::fill(costs.begin() + costly.rayBegin, costs.begin() + costly.rayEnd, 40u);
    // and within it the first half of its rays cost 200: its groups there hold fewer rays.
    const std::uint32_t half = costly.rayBegin + (costly.rayEnd - costly.rayBegin) / 2;
    std::fill(costs.begin() + costly.rayBegin, costs.begin() + half, 200u);
    for (std::uint32_t groups : {1u, 4u, 16u}) {
        const gpu::RayGroups grouping = gpu::costedRayGroups(d, groups, costs);
        expectGroupsTileTheRegions(d, grouping);
        EXPECT_EQ(grouping.rayStart.size(), d.regions.size() * groups) << "every group asked for is given";
        EXPECT_LE(gpu::groupTriangleIds(d, grouping).size(), d.triIds.size() * groups) << "no more triangle ids";
        for (std::size_t k = 0; k < d.regions.size(); ++k)
            if (k != 1 && groups > 1) EXPECT_GT(grouping.groupsOf(1), grouping.groupsOf(k));
        // Each group of region 1 weighs its share of the region, give or take one ray.
        const std::uint32_t count = grouping.groupsOf(1);
        std::uint64_t total = 0;
        for (std::uint32_t i = costly.rayBegin; i < costly.rayEnd; ++i) total += gpu::kRayBaseWeight + costs[i];
        for (std::uint32_t s = grouping.firstSlot[1]; s < grouping.firstSlot[2]; ++s) {
            const std::uint32_t end = s + 1 < grouping.firstSlot[2] ? grouping.rayStart[s + 1] : costly.rayEnd;
            std::uint64_t weight = 0;
            for (std::uint32_t i = grouping.rayStart[s]; i < end; ++i) weight += gpu::kRayBaseWeight + costs[i];
            EXPECT_LE(weight, total / count + gpu::kRayBaseWeight + 200u);
        }
        if (count >= 4) {
            const std::uint32_t first = grouping.firstSlot[1], last = grouping.firstSlot[2] - 1;
            EXPECT_LT(grouping.rayStart[first + 1] - grouping.rayStart[first], costly.rayEnd - grouping.rayStart[last])
                << "a group of the costly half holds fewer rays than one of the cheap half";
        }
    }
}

TEST(WorkPlan, EveryTransferPairCoversEveryRayGroupOnceOnACopyOfItsTriangles) {
    const DividedFrame f(5);
    const Division& d = f.division;
    std::vector<std::uint32_t> costs(d.rayIds.size(), 0);
    for (std::size_t i = 0; i < costs.size(); ++i) costs[i] = std::uint32_t(i * 7 % 23);
    const std::vector<TransferRound> schedule = transferSchedule(d);
    ASSERT_FALSE(schedule.empty());
    for (const gpu::RayGroups& grouping : {gpu::evenRayGroups(d, 3), gpu::costedRayGroups(d, 6, costs)}) {
        const gpu::WorkPlan plan = gpu::planWorkItems(d, schedule, 3, grouping);
        ASSERT_EQ(plan.passes.size(), schedule.size() + 1);
        EXPECT_EQ(plan.passes[0].second, plan.slots.size());
        EXPECT_EQ(plan.triangleIds, gpu::groupTriangleIds(d, grouping).size());
        auto regionOf = [&](std::uint32_t slot) {
            return std::size_t(std::upper_bound(grouping.firstSlot.begin(), grouping.firstSlot.end(), slot) - grouping.firstSlot.begin() - 1);
        };
        std::vector<std::uint32_t> rayUses(plan.slots.size(), 0), triUses(plan.slots.size(), 0);
        std::size_t item = 0;
        for (std::size_t pass = 0; pass < plan.passes.size(); ++pass) {
            std::vector<std::uint32_t> raySlots;
            for (std::uint32_t i = 0; i < plan.passes[pass].second; ++i, ++item) {
                const WorkItem& w = plan.items[item];
                EXPECT_EQ(w.raySeq, rayUses[w.rayRegion]++) << "raySeq counts the earlier items on its ray slot";
                EXPECT_EQ(w.triSeq, triUses[w.triRegion]++) << "triSeq counts the earlier items on its triangle slot";
                raySlots.push_back(w.rayRegion);
                if (pass == 0) EXPECT_EQ(w.triRegion, w.rayRegion);
            }
            // The pass's pairs, each once per ray group of its ray region, on its triangle region's copies.
            std::vector<std::uint32_t> expected;
            const std::size_t firstItem = item - plan.passes[pass].second;
            std::vector<TransferPair> pairs;
            if (pass == 0)
                for (std::uint32_t k = 0; k < d.regions.size(); ++k) pairs.push_back({k, k});
            else
                pairs = schedule[pass - 1].pairs;
            std::size_t at = firstItem;
            for (const TransferPair& p : pairs)
                for (std::uint32_t s = grouping.firstSlot[p.rayRegion]; s < grouping.firstSlot[p.rayRegion + 1]; ++s, ++at) {
                    expected.push_back(s);
                    EXPECT_EQ(regionOf(plan.items[at].triRegion), p.triRegion);
                }
            EXPECT_EQ(raySlots, expected);
        }
        EXPECT_EQ(item, plan.items.size());
    }
}

TEST(WorkPlan, TheEstimateCountsTheTriangleBoundsARayCrosses) {
    const DividedFrame f(3);
    const Division& d = f.division;
    const FrameGeometry& g = f.frame.geometry;
    ASSERT_TRUE(g.raysShareStart);
    ThreadPool pool(2);
    const std::vector<std::uint32_t> costs = gpu::estimateStep1RayCosts(g, d, pool);
    ASSERT_EQ(costs.size(), d.rayIds.size());
    std::size_t crossing = 0, zero = 0;
    for (const Region& r : d.regions)
        for (std::uint32_t i = r.rayBegin; i < r.rayEnd; ++i) {
            const Ray& ray = (*g.rays)[d.rayIds[i]];
            bool crosses = false;
            for (std::uint32_t t = r.triBegin; t < r.triEnd && !crosses; ++t) {
                const Bounds& b = (*g.triangleBounds)[d.triIds[t]];
                float enter = 0.0f, leave = kNoHitT;
                for (int a = 0; a < 3; ++a) {
                    const float t0 = (b.lo[a] - ray.origin[a]) / ray.dir[a], t1 = (b.hi[a] - ray.origin[a]) / ray.dir[a];
                    enter = std::max(enter, std::min(t0, t1));
                    leave = std::min(leave, std::max(t0, t1));
                }
                crosses = enter <= leave;
            }
            if (crosses) {
                ++crossing;
                EXPECT_GE(costs[i], 1u) << "a ray through a triangle's bounds lies in their projection";
            }
            zero += costs[i] == 0;
        }
    EXPECT_GT(crossing, 100u);
    EXPECT_GT(zero, 100u) << "rays beside the shapes meet no bounds";

    std::vector<Ray> scattered = *g.rays;
    scattered[1].origin.x += 1.0f;  // no shared origin: nothing to project from
    FrameGeometry moved = g;
    moved.rays = &scattered;
    moved.raysShareStart = false;
    EXPECT_TRUE(gpu::estimateStep1RayCosts(moved, d, pool).empty());
}

namespace {

// A plan of `slots` slots with the given passes, each a list of (ray slot, triangle slot).
gpu::WorkPlan handMadePlan(std::uint32_t slots,
                           const std::vector<std::pair<std::string, std::vector<std::pair<std::uint32_t, std::uint32_t>>>>& passes) {
    gpu::WorkPlan plan;
    plan.slots.resize(slots);
    for (const auto& [name, items] : passes) {
        plan.passes.emplace_back(name, std::uint32_t(items.size()));
        for (const auto& [ray, tri] : items) {
            WorkItem w{};
            w.rayRegion = ray;
            w.triRegion = tri;
            plan.items.push_back(w);
        }
    }
    return plan;
}

}  // namespace

TEST(WorkPlan, PassesOnDisjointSlotsShareADispatch) {
    using Dispatches = std::vector<std::pair<std::string, std::uint32_t>>;
    // Two regions: each transfer round is one work item, and the two directions touch
    // different slots, so they run together.
    const gpu::WorkPlan two = handMadePlan(2, {{"step1", {{0, 0}, {1, 1}}}, {"toward-low 1", {{1, 0}}}, {"toward-high 1", {{0, 1}}}});
    EXPECT_EQ(gpu::dispatchedPasses(two), (Dispatches{{"step1", 2}, {"toward-low 1 + toward-high 1", 2}}));
    // Three regions: ray slot 1 is in both directions' rounds, which stay apart.
    const gpu::WorkPlan three = handMadePlan(
        3, {{"step1", {{0, 0}, {1, 1}, {2, 2}}}, {"toward-low 1", {{1, 0}, {2, 1}}}, {"toward-high 1", {{0, 1}, {1, 2}}}});
    EXPECT_EQ(gpu::dispatchedPasses(three), (Dispatches{{"step1", 3}, {"toward-low 1", 2}, {"toward-high 1", 2}}));
    // A triangle slot in common keeps passes apart as well; a later pass may join again.
    const gpu::WorkPlan tri = handMadePlan(4, {{"a", {{0, 0}}}, {"b", {{1, 0}}}, {"c", {{2, 2}}}, {"d", {{3, 3}}}});
    EXPECT_EQ(gpu::dispatchedPasses(tri), (Dispatches{{"a", 1}, {"b + c + d", 3}}));
    EXPECT_TRUE(gpu::dispatchedPasses(gpu::WorkPlan{}).empty());
}

TEST(WorkPlan, MergedDispatchesKeepEveryWorkItemInOrderWithoutAWaitInside) {
    for (unsigned regions : {2u, 3u, 5u}) {
        const DividedFrame f(regions);
        const Division& d = f.division;
        for (std::uint32_t groups : {1u, 3u}) {
            SCOPED_TRACE(std::to_string(regions) + " regions, " + std::to_string(groups) + " groups");
            const gpu::WorkPlan plan = gpu::planWorkItems(d, transferSchedule(d), groups, gpu::evenRayGroups(d, groups));
            const auto dispatches = gpu::dispatchedPasses(plan);
            std::size_t pass = 0, first = 0;
            for (const auto& [name, count] : dispatches) {
                // The dispatch is a run of whole passes, named in order; a work item of a later
                // pass of the run shares no slot with the run's earlier passes.
                std::string names;
                std::uint32_t items = 0;
                std::vector<bool> raySlot(plan.slots.size(), false), triSlot(plan.slots.size(), false);
                while (items < count) {
                    ASSERT_LT(pass, plan.passes.size());
                    names += (names.empty() ? "" : " + ") + plan.passes[pass].first;
                    std::vector<bool> rayHere = raySlot, triHere = triSlot;
                    for (std::uint32_t i = 0; i < plan.passes[pass].second; ++i) {
                        const WorkItem& w = plan.items[first + items + i];
                        if (items > 0) EXPECT_FALSE(raySlot[w.rayRegion] || triSlot[w.triRegion]) << name;
                        rayHere[w.rayRegion] = triHere[w.triRegion] = true;
                    }
                    raySlot = rayHere;
                    triSlot = triHere;
                    items += plan.passes[pass++].second;
                }
                EXPECT_EQ(items, count);
                EXPECT_EQ(names, name);
                first += count;
            }
            EXPECT_EQ(pass, plan.passes.size());
            EXPECT_EQ(first, plan.items.size());
        }
    }
}
