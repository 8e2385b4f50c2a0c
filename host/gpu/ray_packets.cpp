#include "gpu/ray_packets.hpp"

#include <algorithm>

#include "cpu/traversal.hpp"
#include "gpu/device_defaults.hpp"

namespace dacrt::gpu {

bool kernelUsesPackets(const FrameGeometry& g, const DacrtOptions& options, const DeviceInfo& device) {
    return options.packets && packetTiles(g) > 0 && g.order == ChildOrder::NearSide && g.query == HitQuery::Closest &&
           loopBudgetOf(device) == 0;
}

PacketSections packetSections(std::uint64_t n, std::uint64_t rays, std::uint64_t packets) {
    return {.scratch = 2 * n, .packetRays = 4 * n, .doneFlags = 5 * n, .packetIds = 5 * n + rays,
            .end = 5 * n + rays + 2 * packets};
}

namespace {

// Bounds of the direction reciprocals of rays packetRays[begin, end).
PacketBounds boundPacket(const FrameGeometry& g, const std::vector<std::uint32_t>& packetRays, std::uint32_t begin,
                         std::uint32_t end) {
    const RayPacket bounds = simd::boundsOfRays(g.rays->data(), packetRays.data() + begin, end - begin);
    PacketBounds p{};
    p.invLo = bounds.invLo;
    p.invHi = bounds.invHi;
    p.unboundedAxes = bounds.unboundedAxes;
    p.rayBegin = begin;
    p.rayEnd = end;
    return p;
}

}  // namespace

RayPackets buildRayPackets(const FrameGeometry& g, const std::vector<std::uint32_t>& rayIds,
                           const std::vector<Region>& slots, ThreadPool& pool) {
    const std::uint32_t width = g.imageWidth;
    const std::uint32_t tileColumns = (width + kPacketTile - 1) / kPacketTile;
    auto tileRow = [&](std::uint32_t id) { return id / width / kPacketTile; };
    auto tileColumn = [&](std::uint32_t id) { return id % width / kPacketTile; };
    RayPackets out;
    out.packetRays.resize(rayIds.size());
    // Slots hold disjoint ranges of the ids: each is grouped on its own, its packets apart.
    std::vector<std::vector<PacketBounds>> slotPackets(slots.size());
    pool.parallelFor(slots.size(), [&](std::size_t s, unsigned) {
        const Region& slot = slots[s];
        std::vector<std::uint32_t> start(tileColumns + 1);
        for (std::uint32_t runBegin = slot.rayBegin; runBegin < slot.rayEnd;) {
            const std::uint32_t row = tileRow(rayIds[runBegin]);
            std::uint32_t runEnd = runBegin;
            while (runEnd < slot.rayEnd && tileRow(rayIds[runEnd]) == row) ++runEnd;
            // A counting sort of the run by tile column; start[c] then ends column c's rays.
            std::fill(start.begin(), start.end(), 0u);
            for (std::uint32_t k = runBegin; k < runEnd; ++k) ++start[tileColumn(rayIds[k]) + 1];
            for (std::uint32_t c = 0; c < tileColumns; ++c) start[c + 1] += start[c];
            for (std::uint32_t k = runBegin; k < runEnd; ++k)
                out.packetRays[runBegin + start[tileColumn(rayIds[k])]++] = rayIds[k];
            std::uint32_t columnBegin = 0;
            for (std::uint32_t c = 0; c < tileColumns; columnBegin = start[c], ++c)
                if (start[c] > columnBegin)
                    slotPackets[s].push_back(boundPacket(g, out.packetRays, runBegin + columnBegin, runBegin + start[c]));
            runBegin = runEnd;
        }
    });
    out.slotFirstPacket.reserve(slots.size() + 1);
    for (const std::vector<PacketBounds>& packets : slotPackets) {
        out.slotFirstPacket.push_back(std::uint32_t(out.packets.size()));
        out.packets.insert(out.packets.end(), packets.begin(), packets.end());
    }
    out.slotFirstPacket.push_back(std::uint32_t(out.packets.size()));
    return out;
}

}  // namespace dacrt::gpu
