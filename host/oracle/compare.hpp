#pragma once
// Two AOV images compared pixel by pixel: the gate a CI job puts between a cpu and a gpu render.
#include <cstdint>
#include <string>
#include <vector>

#include "core/enum_names.hpp"
#include "core/image_io.hpp"

namespace dacrt {

// Two hits that differ in primitive are a near tie when their depths agree within this
// relative bound: a watertight single-precision test resolves hits no closer than about
// 2^-20 of the distance reliably, so a few times that separates "same surface point, other
// triangle" (an edge or a coincident face) from a different surface.
constexpr double kNearTieRelativeDepth = 1e-5;

struct CompareOptions {
    double nearTieBound = kNearTieRelativeDepth;  // relative depth of a near tie
    double depthTolerance = 0.0;  // same primitive, depths within this relative bound: tolerated (0: bitwise)
};

// What a pixel is, compared.
enum class PixelComparison : std::uint8_t { Identical, NearTie, ToleratedDepth, Differs };

enum class CompareVerdict { Identical, NearTiesOnly, Differs };
template <>
struct EnumNames<CompareVerdict> {
    static constexpr std::array<std::pair<CompareVerdict, std::string_view>, 3> table{
        {{CompareVerdict::Identical, "identical"},
         {CompareVerdict::NearTiesOnly, "near ties only"},
         {CompareVerdict::Differs, "differs"}}};
};

struct CompareReport {
    std::uint64_t pixels = 0;
    std::uint64_t differingPrimId = 0;
    std::uint64_t differingDepth = 0;    // bitwise
    std::uint64_t differingHitMask = 0;  // one hits, the other misses
    std::uint64_t nearTies = 0;          // prim ids differ, depths within nearTieBound
    std::uint64_t toleratedDepth = 0;    // same prim id, depths within depthTolerance but not equal
    std::uint64_t differingVisibility = 0;  // pixels whose secondary-pass channels (shadow.*, ao) differ
    std::uint64_t realDifferences = 0;   // pixels that are neither identical, near ties nor tolerated
    double maxRelDepthDiff = 0.0;        // over pixels both hit
    double rmsRelDepthDiff = 0.0;
    CompareOptions options;
    std::vector<PixelComparison> perPixel;  // row-major

    CompareVerdict verdict() const;
    std::string verdictLine() const;  // "compare: identical", "compare: near ties only (N pixels)", ...
    std::string json() const;
    std::string text() const;
};

// The secondary passes' channels (Aov::extra) are compared bitwise where both images have them:
// a pixel where any differs is a real difference; a channel only one image has is an error.
CompareReport compareAovs(const Aov& a, const Aov& b, const CompareOptions& options = {});

// An 8-bit RGB picture of the comparison: image a's surfaces in grey (lit by their normals),
// misses dark, near ties and tolerated depths yellow, real differences red.
std::vector<std::uint8_t> differenceImage(const Aov& a, const CompareReport& report);

}  // namespace dacrt
