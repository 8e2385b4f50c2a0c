#include "peers/embree_in_loop.hpp"

#include <algorithm>
#include <exception>

#include "core/errors.hpp"
#include "peers/embree_packets.hpp"

namespace dacrt {
namespace {

// Primary pixels per work unit of a secondary pass: a few thousand rays at --ao 4, as many as
// the stored rays' runs hold, so that the pool's hand-out costs nothing next to them and a
// frame still balances over the threads.
constexpr std::size_t kPixelsPerRun = 1024;

// A run's secondary rays, 16 to a packet in the order they are made, each packet traced for
// occlusion once it is full (and the last one, partly full, by flush) and its answers written
// to their slots.
class OcclusionPackets {
public:
    OcclusionPackets(RTCScene scene, Hit* slots) : scene_(scene), slots_(slots) {}

    void add(std::uint32_t slot, const Ray& ray) {
        packet_.rays[lanes_] = embree::laneRayOf(ray);
        slot_[lanes_++] = slot;
        if (lanes_ == 16) flush();
    }

    // The lanes left traces a copy of the first ray, masked out.
    void flush() {
        if (lanes_ == 0) return;
        for (int l = 0; l < 16; ++l) {
            packet_.valid[l] = l < lanes_ ? -1 : 0;
            if (l >= lanes_) packet_.rays[l] = packet_.rays[0];
        }
        Hit answers[16];
        embree::occluded16(scene_, packet_, false, answers);
        for (int l = 0; l < lanes_; ++l) slots_[slot_[l]] = answers[l];
        traced_ += std::uint64_t(lanes_);
        lanes_ = 0;
    }

    std::uint64_t traced() const { return traced_; }

private:
    RTCScene scene_;
    Hit* slots_;
    embree::Packet16 packet_;
    std::uint32_t slot_[16];
    int lanes_ = 0;
    std::uint64_t traced_ = 0;
};

}  // namespace

void traceCameraInLoop(const EmbreeScene& scene, const PixelRays& pixels, ThreadPool& pool, std::vector<Hit>& hits) {
    const std::size_t width = std::size_t(pixels.width());
    hits.resize(width * std::size_t(pixels.height()));
    embree::traceTiles(
        width, hits.size(), pool,
        [&](const embree::Tile& tile) {
            // The tile's rays as primaryRays makes them, 16 lanes in SIMD (their origin and dir;
            // the reciprocals and shear are dacrt's alone), one at a time where it cannot.
            Ray rays[16];
            for (int l = pixels.tileDirections(int(tile.x0), int(tile.y0), rays); l < 16; ++l)
                if (tile.inside[l]) rays[l] = pixels.ray(int(tile.x0) + l % 4, int(tile.y0) + l / 4);
            const auto rayOfLane = [&](int l) {
                return embree::LaneRay{rays[l].origin, 0.0f, rays[l].dir, kNoHitT};  // makeRay's segment
            };
            embree::traceTile(scene.handle(), tile, HitQuery::Closest, rayOfLane, hits.data());
        },
        [&] { return scene.pendingError("rtcIntersect16"); });
}

std::uint64_t occludeSecondaryInLoop(const EmbreeScene& scene, const SecondaryPass& pass, const PixelRays& pixels,
                                     const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                     ThreadPool& pool, std::vector<Hit>& slots) {
    const std::size_t width = std::size_t(pixels.width());
    if (primaryHits.size() != width * std::size_t(pixels.height()))
        throw InternalError("a secondary pass got " + std::to_string(primaryHits.size()) + " primary hits for " +
                            std::to_string(width * std::size_t(pixels.height())) + " pixels");
    slots.resize(secondarySlots(pass, primaryHits.size()));
    const Hit notTraced{0.0f, kNotTracedPrim, 0.0f, 0.0f};
    const std::size_t runs = (primaryHits.size() + kPixelsPerRun - 1) / kPixelsPerRun;
    std::vector<std::uint64_t> made(pool.size(), 0);
    embree::FirstFailure failure;
    pool.parallelFor(runs, [&](std::size_t run, unsigned worker) {
        const embree::FlushDenormals ftz;
        try {
            OcclusionPackets packets(scene.handle(), slots.data());
            const std::size_t first = run * kPixelsPerRun, end = std::min(primaryHits.size(), first + kPixelsPerRun);
            std::fill(slots.begin() + std::ptrdiff_t(first * pass.raysPerHit),
                      slots.begin() + std::ptrdiff_t(end * pass.raysPerHit), notTraced);
            // The rays as dacrt's passes make them (occlusion rays several at a time), each
            // packet's 16 in the order they are made.
            secondaryRaysOfRange(
                pass, first, end, primaryHits.data(),
                [&](std::size_t i) { return pixels.ray(int(i % width), int(i / width)); }, triangles,
                [&](std::uint32_t slot, const Ray& ray) { packets.add(slot, ray); });
            packets.flush();
            made[worker] += packets.traced();
        } catch (...) {
            failure.keep(std::current_exception());
        }
        failure.keepError(scene.pendingError("rtcOccluded16"));
    });
    failure.rethrow();
    std::uint64_t total = 0;
    for (const std::uint64_t n : made) total += n;
    return total;
}

}  // namespace dacrt
