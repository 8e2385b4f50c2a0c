// The gpu kernel's ray packets, on the host: each slot's rays grouped by 8x8 tile at the slot's
// own positions, and bounds that hold every ray's direction reciprocals.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/procedural.hpp"
#include "core/thread_pool.hpp"
#include "cpu/traversal.hpp"
#include "gpu/ray_packets.hpp"
#include "gpu/work_plan.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

Scene shapes() {
    return sceneFromMeshes({icosphere({-0.5f, 0.0f, 0.0f}, 0.6f, 3), box({0.2f, -0.5f, -0.5f}, {0.9f, 0.5f, 0.4f})});
}

std::uint32_t tileOf(std::uint32_t id, std::uint32_t width) {
    const std::uint32_t columns = (width + kPacketTile - 1) / kPacketTile;
    return id / width / kPacketTile * columns + id % width / kPacketTile;
}

}  // namespace

TEST(RayPackets, EachSlotsRaysGroupedByTileWithinBoundsThatHoldThem) {
    // 45x29: tiles cut at the right and bottom edges; three regions of two ray groups each.
    const std::uint32_t width = 45, height = 29;
    const Frame frame(shapes(), defaultCamera(shapes(), width, height), width, height);
    ThreadPool pool(2);
    MemoryPlan plan;
    const Division division = divideScene(frame.geometry, 3, 0, pool, plan);
    const std::vector<Region> slots = gpu::groupRegions(division, gpu::evenRayGroups(division, 2));
    const gpu::RayPackets packets = gpu::buildRayPackets(frame.geometry, division.rayIds, slots, pool);
    ASSERT_EQ(packets.slotFirstPacket.size(), slots.size() + 1);
    ASSERT_EQ(packets.packetRays.size(), division.rayIds.size());
    EXPECT_EQ(packets.slotFirstPacket.back(), packets.packets.size());
    std::size_t tiled = 0;
    for (std::size_t s = 0; s < slots.size(); ++s) {
        const Region& slot = slots[s];
        // The slot's positions hold the slot's ids, regrouped.
        std::vector<std::uint32_t> ids(division.rayIds.begin() + slot.rayBegin, division.rayIds.begin() + slot.rayEnd);
        std::vector<std::uint32_t> grouped(packets.packetRays.begin() + slot.rayBegin, packets.packetRays.begin() + slot.rayEnd);
        std::sort(ids.begin(), ids.end());
        std::sort(grouped.begin(), grouped.end());
        EXPECT_EQ(ids, grouped) << "slot " << s;
        std::uint32_t next = slot.rayBegin;  // packets cover the slot's range in order
        std::vector<std::uint32_t> tilesSeen;
        for (std::uint32_t p = packets.slotFirstPacket[s]; p < packets.slotFirstPacket[s + 1]; ++p) {
            const PacketBounds& packet = packets.packets[p];
            EXPECT_EQ(packet.rayBegin, next);
            ASSERT_LT(packet.rayBegin, packet.rayEnd);
            EXPECT_LE(packet.rayEnd - packet.rayBegin, kPacketTile * kPacketTile);
            next = packet.rayEnd;
            const std::uint32_t tile = tileOf(packets.packetRays[packet.rayBegin], width);
            tilesSeen.push_back(tile);
            for (std::uint32_t k = packet.rayBegin; k < packet.rayEnd; ++k) {
                const std::uint32_t id = packets.packetRays[k];
                EXPECT_EQ(tileOf(id, width), tile) << "ray " << id;
                const glm::vec3& inv = (*frame.geometry.rays)[id].invDir;
                for (int a = 0; a < 3; ++a) {
                    if (inv[a] == 0.0f || !std::isfinite(inv[a])) {
                        EXPECT_TRUE((packet.unboundedAxes >> a) & 1u);
                        continue;
                    }
                    EXPECT_LE(packet.invLo[a], inv[a]);
                    EXPECT_GE(packet.invHi[a], inv[a]);
                }
            }
        }
        EXPECT_EQ(next, slot.rayEnd);
        std::sort(tilesSeen.begin(), tilesSeen.end());
        EXPECT_EQ(std::adjacent_find(tilesSeen.begin(), tilesSeen.end()), tilesSeen.end()) << "one packet per tile";
        tiled += tilesSeen.size();
    }
    EXPECT_GT(tiled, slots.size()) << "expected several tiles per slot";
}

TEST(RayPackets, SectionsOfTheRayIdBufferFollowEachOther) {
    const gpu::PacketSections at = gpu::packetSections(100, 120, 7);
    EXPECT_EQ(at.scratch, 200u);      // ids [0, 100), gathered rays [100, 200), scratch of both
    EXPECT_EQ(at.packetRays, 400u);
    EXPECT_EQ(at.doneFlags, 500u);
    EXPECT_EQ(at.packetIds, 620u);    // a flag per ray
    EXPECT_EQ(at.end, 634u);          // packet ids and their scratch
}
