#pragma once
// The float64 reference of the benchmark: what every backend's error is measured against.
//
// It is a DACRT of its own (not the float32 traversal with wider types): boxes, slab tests,
// filters, the watertight test and the tie rule all in float64, over the float32 rays and
// triangles widened exactly. Brute force in float64 would be simpler but costs 21e9 tests per
// Bunny frame; tests check this tracer against it on small scenes, hit for hit.
//
// Why float64 is exact enough: the inputs are exactly representable, and the watertight
// test's rounding in float64 is about 2^-29 of float32's. A float64 answer can differ from
// the exact one only where two hits lie within ~1e-15 relative of each other, or a ray
// passes within ~1e-15 of an edge: ten orders of magnitude inside the benchmark's near-tie
// band (1e-5), so it never turns a backend's real error into a near tie or back.
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "core/thread_pool.hpp"

namespace dacrt {

struct ReferenceHit {
    double t = 0.0;                  // +inf on a miss
    std::uint32_t prim = kMissPrim;  // ties: lowest id, as in every backend
};

// Closest hit (t > ray.tmin) of every ray; chunks of consecutive rays run on the pool.
std::vector<ReferenceHit> traceReference(const std::vector<Triangle>& triangles, const std::vector<Ray>& rays,
                                         ThreadPool& pool);

// Every ray against every triangle in float64: the oracle of the reference itself (tests).
std::vector<ReferenceHit> traceReferenceBrute(const std::vector<Triangle>& triangles, const std::vector<Ray>& rays,
                                              ThreadPool& pool);

// Reads or writes a cached reference frame (raw little-endian records behind a header that
// holds `key` and the ray count). readReferenceCache returns false when the file is
// missing or was written for another key; a damaged file (truncated, too long, a primitive
// id not below triangleCount, an impossible t) is an error.
bool readReferenceCache(const std::string& path, const std::string& key, std::size_t rays, std::size_t triangleCount,
                        std::vector<ReferenceHit>& hits);
void writeReferenceCache(const std::string& path, const std::string& key, const std::vector<ReferenceHit>& hits);

}  // namespace dacrt
