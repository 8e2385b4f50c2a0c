#pragma once
// The gpu kernel's ray packets (shaders/ray_packets.glsl): each ray slot's rays grouped by the
// 8x8 pixel tile they belong to, with bounds of their direction reciprocals, so that the top
// of each work item's tree filters a packet where it would filter some 64 rays.
#include <cstdint>
#include <vector>

#include <dacrt/options.hpp>

#include "core/shader_layout.hpp"
#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "gpu/context.hpp"

namespace dacrt::gpu {

// Whether the kernel traces this frame's rays in packets: primary rays of an image (they share
// their start and have a tile), packets on (`options`, resolved), closest hits in a common
// child order, and no loop budget (a work item with packets never runs in slices).
bool kernelUsesPackets(const FrameGeometry& geometry, const DacrtOptions& options, const DeviceInfo& device);

// Where the ray id buffer's sections begin, in ids, when the kernel traces packets
// (DacrtPush::packetRaysAt): n ray ids, n gathered from packets, a scratch half of 2n, the
// packet rays (n), a flag per ray, the packet ids and as many of their scratch; `end` is the
// buffer's length.
struct PacketSections {
    std::uint64_t scratch = 0, packetRays = 0, doneFlags = 0, packetIds = 0, end = 0;
};
PacketSections packetSections(std::uint64_t rayIds, std::uint64_t rays, std::uint64_t packets);

struct RayPackets {
    // As long as the division's ray ids: each slot's ray ids grouped by tile, at the slot's
    // own positions (DacrtPush::packetRaysAt).
    std::vector<std::uint32_t> packetRays;
    std::vector<PacketBounds> packets;          // slot after slot, each slot's by tile
    std::vector<std::uint32_t> slotFirstPacket; // one per slot, and the packet count
};

// The packets of every slot (slots: [rayBegin, rayEnd) of rayIds each). Rays of a slot come in
// pixel order, so those of one row of tiles are a run, grouped by a counting sort of its tile
// columns; the slots in parallel.
RayPackets buildRayPackets(const FrameGeometry& geometry, const std::vector<std::uint32_t>& rayIds,
                           const std::vector<Region>& slots, ThreadPool& pool);

}  // namespace dacrt::gpu
