#pragma once
// What both Embree tracers share (peers/embree_tracer.cpp traces rays made before it;
// peers/embree_in_loop.cpp makes each packet's rays in its loop): a ray as a packet's lane,
// the 16-wide calls with their answers as dacrt's hits, the 4x4 pixel tiles a camera's rays
// are dealt in, FTZ/DAZ on the tracing threads, and the first failure of the pool's threads.
// Private to the peers layer (it includes Embree's header).
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <string>

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"  // HitQuery
#include "cpu/trace_result.hpp"

namespace dacrt::embree {

// Flush-to-zero and denormals-are-zero for the calling thread while it lives, as Embree
// recommends for speed; the previous mode comes back after (dacrt's tracers share the threads).
class FlushDenormals {
public:
    FlushDenormals() : csr_(_mm_getcsr()) {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    }
    ~FlushDenormals() { _mm_setcsr(csr_); }

private:
    unsigned csr_;
};

// What Embree reads of a ray: its origin and direction, and dacrt's segment (tmin < t <= tmax,
// tmax kNoHitT for a whole ray).
struct LaneRay {
    glm::vec3 origin;
    float tmin = 0.0f;
    glm::vec3 dir;
    float tmax = kNoHitT;
};

inline LaneRay laneRayOf(const Ray& ray) { return LaneRay{ray.origin, ray.tmin, ray.dir, ray.tmax}; }

// A packet's rays and mask (-1: traced, 0: not), 64-byte aligned as the 16-wide calls want
// them. Lanes left out carry a copy of a traced lane's ray: they are masked out, but their
// fields must still be finite.
struct Packet16 {
    LaneRay rays[16];
    alignas(64) int valid[16];
};

// The packet's closest hits (rtcIntersect16; coherent: rays of one camera through neighbouring
// pixels) into hits[l] for the traced lanes: missHit(ray) for a miss.
void intersect16(RTCScene scene, const Packet16& packet, bool coherent, Hit (&hits)[16]);

// The packet's occlusion (rtcOccluded16), which stops at any hit and names none of it: an
// occluded ray gets Hit{ray.tmin, kUnnamedHitPrim, 0, 0}, t being only a bound the hit lies
// beyond, an unoccluded one missHit(ray).
void occluded16(RTCScene scene, const Packet16& packet, bool coherent, Hit (&hits)[16]);

// Single rays (rtcIntersect1, rtcOccluded1), with the packets' answers.
Hit intersect1(RTCScene scene, const LaneRay& ray);
Hit occluded1(RTCScene scene, const LaneRay& ray);

// One 4x4 tile of an image's pixels: its top-left pixel, and per lane (x + 4 y within the
// tile) the pixel's index, row by row, and whether it lies in the image.
struct Tile {
    std::uint32_t x0 = 0, y0 = 0;
    std::size_t index[16];
    bool inside[16];
};

// The tile's rays traced as one coherent packet for the query, each answer written to
// hits[tile.index[l]]: lane l traces rayOf(l) (a LaneRay) where its pixel lies in the image; a
// lane outside traces a copy of the first lane inside, masked out. A tile with no pixel
// inside traces nothing.
template <typename RayOfLane>
void traceTile(RTCScene scene, const Tile& tile, HitQuery query, RayOfLane&& rayOf, Hit* hits) {
    int first = 0;
    while (first < 16 && !tile.inside[first]) ++first;
    if (first == 16) return;
    Packet16 packet;
    for (int l = 0; l < 16; ++l) {
        packet.valid[l] = tile.inside[l] ? -1 : 0;
        packet.rays[l] = rayOf(tile.inside[l] ? l : first);
    }
    Hit answers[16];
    if (query == HitQuery::Any) occluded16(scene, packet, true, answers);
    else intersect16(scene, packet, true, answers);
    for (int l = 0; l < 16; ++l)
        if (tile.inside[l]) hits[tile.index[l]] = answers[l];
}

// The first failure of the pool's threads, which must not throw (nothing would catch it
// there), thrown by rethrow() on the calling thread once every work unit is done.
class FirstFailure {
public:
    void keep(std::exception_ptr failure);
    // A failed Embree call's text (empty: none failed).
    void keepError(const std::string& error);
    void rethrow() const;

private:
    std::mutex mutex_;
    std::exception_ptr first_;
};

// Every tile of an image of `pixels` pixels, `width` a row (the last row may be partial), a
// row of tiles per work unit on the pool, with FTZ/DAZ on. traceTile(tile) runs on the pool's
// threads; what it throws is kept, and after each row checkRow() returns the text of a failed
// Embree call (empty: none). Throws the first failure once every row is done.
template <typename TraceTile, typename CheckRow>
void traceTiles(std::size_t width, std::size_t pixels, ThreadPool& pool, TraceTile&& traceTile, CheckRow&& checkRow) {
    const std::size_t height = (pixels + width - 1) / width;
    const std::size_t tileColumns = (width + 3) / 4, tileRows = (height + 3) / 4;
    FirstFailure failure;
    pool.parallelFor(tileRows, [&](std::size_t row, unsigned) {
        const FlushDenormals ftz;
        try {
            for (std::size_t column = 0; column < tileColumns; ++column) {
                Tile tile;
                tile.x0 = std::uint32_t(column * 4);
                tile.y0 = std::uint32_t(row * 4);
                for (std::uint32_t l = 0; l < 16; ++l) {
                    const std::size_t x = tile.x0 + l % 4, y = tile.y0 + l / 4;
                    tile.index[l] = y * width + x;
                    tile.inside[l] = x < width && tile.index[l] < pixels;
                }
                traceTile(tile);
            }
        } catch (...) {
            failure.keep(std::current_exception());
        }
        failure.keepError(checkRow());
    });
    failure.rethrow();
}

}  // namespace dacrt::embree
