#pragma once
// Embree as a renderer on it runs: each packet's rays made inside the tracing loop and traced
// at once, never a frame of rays stored. Primary rays are made per 4x4 pixel tile (PixelRays:
// core's primaryRays arithmetic, so the rays, and the hits, are those of EmbreeScene::trace on
// the stored rays, bit for bit), shadow and occlusion rays per 16-wide packet from the primary
// hits (secondaryRaysOfRange: makeSecondaryRays' rays). Work goes to the pool's threads in rows of
// tiles or runs of pixels, with FTZ/DAZ on (restored afterwards).
#include <cstdint>
#include <vector>

#include "core/camera.hpp"
#include "core/thread_pool.hpp"
#include "cpu/secondary_rays.hpp"
#include "peers/embree_tracer.hpp"

namespace dacrt {

// The camera's closest hits, one per pixel row by row, into `hits` (resized to the image: a
// renderer's frame buffer, whose memory the caller keeps from frame to frame), by rtcIntersect16
// with the coherent flag per tile. Throws std::runtime_error with Embree's error text, or the
// InputError primaryRays would throw for a ray of the camera.
void traceCameraInLoop(const EmbreeScene& scene, const PixelRays& pixels, ThreadPool& pool, std::vector<Hit>& hits);

// A secondary pass of that frame: from `primaryHits` (one per pixel of `pixels`) over the
// triangles the scene was built on, its rays made per packet and traced for occlusion
// (rtcOccluded16), one answer per slot into `slots` (resized to secondarySlots; memory kept as
// above): Hit{0, kNotTracedPrim} where no ray was made, else EmbreeScene::trace's answer for
// the ray. Returns the rays made. Throws as above, and InputError where the pass has more slots
// than it can hold.
std::uint64_t occludeSecondaryInLoop(const EmbreeScene& scene, const SecondaryPass& pass, const PixelRays& pixels,
                                     const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                     ThreadPool& pool, std::vector<Hit>& slots);

}  // namespace dacrt
