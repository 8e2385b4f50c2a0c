#pragma once
#include <cstdint>
#include <string>

#include "core/image_io.hpp"

namespace dacrt {

// Two hits that differ in primitive are a near tie when their depths agree within this
// relative bound: a watertight single-precision test resolves hits no closer than about
// 2^-20 of the distance reliably, so a few times that separates "same surface point, other
// triangle" (an edge or a coincident face) from a different surface.
constexpr double kNearTieRelativeDepth = 1e-5;

struct CompareReport {
    std::uint64_t pixels = 0;
    std::uint64_t differingPrimId = 0;
    std::uint64_t differingDepth = 0;    // bitwise
    std::uint64_t differingHitMask = 0;  // one hits, the other misses
    std::uint64_t nearTies = 0;
    double maxRelDepthDiff = 0.0;        // over pixels both hit
    double rmsRelDepthDiff = 0.0;
    double nearTieBound = kNearTieRelativeDepth;
    std::string json() const;
    std::string text() const;
};

CompareReport compareAovs(const Aov& a, const Aov& b, double nearTieBound = kNearTieRelativeDepth);

}  // namespace dacrt
