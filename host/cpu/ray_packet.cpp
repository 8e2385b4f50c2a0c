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

}  // namespace dacrt
