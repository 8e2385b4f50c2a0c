#pragma once
// A backend's error against the float64 reference, pixel by pixel (docs/benchmarks.md).
//
// A pixel whose primitive differs from the reference is a near tie when a perturbation of
// the ray by the tolerance below could produce either answer; otherwise it is a real error:
// - both hit: the backend's triangle passes within the tolerance of the ray, at a depth
//   within the tolerance of the reference depth (another triangle at the same surface point:
//   a shared edge, a vertex, a coincident face);
// - the backend misses (a leak): the reference hit lies within the tolerance of its
//   triangle's boundary and the surface ends there (a silhouette, where the neighbour folds
//   back, or a hole's rim). A miss where the surface continues across that boundary is a real
//   leak: a watertight test never lets a ray through between two triangles sharing an edge;
// - the backend hits where the reference misses: its triangle passes within the tolerance.
// The tolerance is kNearTieRelativeDepth (1e-5, about 170 float32 ulps) times the larger of
// the hit distance and the scene's coordinate magnitude (rays have unit directions).
#include <cstdint>
#include <vector>

#include "oracle/reference_tracer.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"

namespace dacrt {

struct ErrorMetrics {
    std::uint64_t pixels = 0;
    std::uint64_t differingPrim = 0;
    std::uint64_t nearTies = 0;
    std::uint64_t realErrors = 0;    // differingPrim - nearTies
    std::uint64_t leaks = 0;         // the reference hits, the backend misses
    std::uint64_t realLeaks = 0;     // leaks that are real errors
    std::uint64_t spuriousHits = 0;  // the backend hits, the reference misses
    std::uint64_t bothHit = 0;
    double maxRelDepth = 0.0;        // |t - t_ref| / t_ref over pixels both hit
    double sumSqRelDepth = 0.0;
    double sumSqShaded = 0.0;        // squared 8-bit sRGB differences of the shaded images
    std::uint64_t shadedSamples = 0;

    void add(const ErrorMetrics& o);
    double rmsRelDepth() const;
    double realErrorFraction() const { return pixels ? double(realErrors) / double(pixels) : 0.0; }
    double psnr() const;  // dB; +inf when the shaded images are identical
};

// Compares one frame. shadedBackend and shadedReference are 8-bit RGB images of the same
// size as the rays (see shadeImage in image_io.hpp).
ErrorMetrics measureErrors(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                           const std::vector<Ray>& rays, const std::vector<ReferenceHit>& reference,
                           const std::vector<Hit>& hits, const std::vector<std::uint8_t>& shadedReference,
                           const std::vector<std::uint8_t>& shadedBackend, ThreadPool& pool);

}  // namespace dacrt
