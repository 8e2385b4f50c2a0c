#pragma once
// Rays that share their start, bounded together: a frame's 8x8 pixel tiles as packets of the
// DACRT (traversal.hpp), and a leaf's groups of rays (simd_kernels.hpp).
#include <cmath>
#include <cstdint>

#include "core/scene.hpp"

namespace dacrt {

// A packet: the live rays of one 8x8 pixel tile, and bounds of their direction reciprocals
// per axis. Rays that share their start compute (lo - origin) * invDir with the same first
// factor, and rounding is monotone, so the packet's four corner products bound every ray's
// rounded slab values: a packet the bounds reject holds no ray the ray filter would keep.
// Some axes are left unbounded (addToPacketBounds).
struct RayPacket {
    std::uint32_t begin = 0, end = 0;  // its rays: packetRays[begin, end)
    glm::vec3 invLo{0.0f}, invHi{0.0f};
    std::uint32_t unboundedAxes = 0;   // bit per axis
};
constexpr std::uint32_t kPacketTile = 8;

// A packet's bounds with no ray yet, then grown by each ray's invDir. An axis where some ray's
// invDir is 0 (the ray filter's branch) or not finite (no product could be trusted) gets no
// bound. The rule simd::boundsOfRays computes lanes at a time for the cpu's packets and leaf
// groups and the gpu's PacketBounds (shaders/layout.h), and the kernel's leaf groups per
// subgroup (dacrt_workgroup.glsl, subgroupRaysBounds).
template <typename Packet>
void startPacketBounds(Packet& p) {
    p.invLo = glm::vec3(kNoHitT);
    p.invHi = glm::vec3(-kNoHitT);
    p.unboundedAxes = 0;
}
template <typename Packet>
void addToPacketBounds(Packet& p, const glm::vec3& invDir) {
    for (int a = 0; a < 3; ++a) {
        if (invDir[a] == 0.0f || !std::isfinite(invDir[a])) p.unboundedAxes |= 1u << a;
        p.invLo[a] = std::min(p.invLo[a], invDir[a]);
        p.invHi[a] = std::max(p.invHi[a], invDir[a]);
    }
}

// rayIds[0, count), ids of a frame's pixel rays (id = y * imageWidth + x), copied into sorted
// by their 8x8 tile (tiles row-major, tilesX = ceil(imageWidth / 8) a row), each tile's ids in
// their order in rayIds: a stable counting sort over `tiles` tiles. tileEnds (tiles + 1
// entries) comes out with tileEnds[t] where tile t's ids end in sorted (its begin: the end of
// the tile before, or 0). It goes run by run of consecutive ids within a tile's row (up to
// eight pixels, fewer in the last column of a width that is not a multiple of 8): one division
// a run, and a count or slot kept in a register through it, where each id divided and waited
// on the store of the one before it to the same counter.
void sortRaysByTile(const std::uint32_t* rayIds, std::uint32_t count, std::uint32_t imageWidth, std::uint32_t tiles,
                    std::uint32_t* tileEnds, std::uint32_t* sorted);

// The packet filter: false only where shared::rayMayCrossCell(ray, cell, tmax) is false for
// every ray of p (origin and tmin: the rays' shared start).
bool packetMayCrossCell(const RayPacket& p, const glm::vec3& origin, float tmin, const Box& cell);

}  // namespace dacrt
