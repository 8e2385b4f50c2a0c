#include "cpu/ray_packet.hpp"

#include <algorithm>

namespace dacrt {

// Conservative for every ray of the packet (see RayPacket): false only where the ray filter
// would reject each of them.
bool packetMayCrossCell(const RayPacket& p, const glm::vec3& origin, float tmin, const Box& cell) {
    float tNear = -kNoHitT, tFar = kNoHitT;
    for (int a = 0; a < 3; ++a) {
        if ((p.unboundedAxes >> a) & 1u) continue;
        const float d0 = cell.lo[a] - origin[a], d1 = cell.hi[a] - origin[a];  // the ray filter's own first factors
        const float q0 = d0 * p.invLo[a], q1 = d0 * p.invHi[a], q2 = d1 * p.invLo[a], q3 = d1 * p.invHi[a];
        tNear = std::max(tNear, std::min(std::min(q0, q1), std::min(q2, q3)));
        tFar = std::min(tFar, std::max(std::max(q0, q1), std::max(q2, q3)));
    }
    return tNear <= tFar && tFar >= tmin;
}

void sortRaysByTile(const std::uint32_t* rayIds, std::uint32_t count, std::uint32_t imageWidth, std::uint32_t tiles,
                    std::uint32_t* tileEnds, std::uint32_t* sorted) {
    const std::uint32_t tilesX = (imageWidth + kPacketTile - 1) / kPacketTile;
    auto tileOf = [&](std::uint32_t id) { return (id / imageWidth / kPacketTile) * tilesX + (id % imageWidth) / kPacketTile; };
    std::uint32_t* start = tileEnds;  // start[t]: where tile t's rays begin, until they are placed
    std::fill(start, start + tiles + 1, 0u);
    auto forEachRun = [&](auto&& onRun) {
        for (std::uint32_t k = 0; k < count;) {
            const std::uint32_t id = rayIds[k];
            const std::uint32_t x = id % imageWidth;
            const std::uint32_t idsLeftInTileRow = std::min(kPacketTile - x % kPacketTile, imageWidth - x);
            std::uint32_t runEnd = k + 1;
            while (runEnd < count && runEnd - k < idsLeftInTileRow && rayIds[runEnd] == id + (runEnd - k)) ++runEnd;
            onRun(tileOf(id), k, runEnd);
            k = runEnd;
        }
    };
    forEachRun([&](std::uint32_t tile, std::uint32_t runBegin, std::uint32_t runEnd) { start[tile + 1] += runEnd - runBegin; });
    for (std::uint32_t t = 0; t < tiles; ++t) start[t + 1] += start[t];
    forEachRun([&](std::uint32_t tile, std::uint32_t runBegin, std::uint32_t runEnd) {
        std::copy(rayIds + runBegin, rayIds + runEnd, sorted + start[tile]);
        start[tile] += runEnd - runBegin;
    });
}

}  // namespace dacrt
