#include "oracle/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace dacrt {
namespace {

double relativeDifference(float a, float b) {
    const double da = a, db = b;
    const double rel = std::abs(da - db) / std::max(std::abs(da), std::abs(db));
    return std::isfinite(rel) ? rel : 0.0;
}

}  // namespace

CompareReport compareAovs(const Aov& a, const Aov& b, const CompareOptions& options) {
    if (a.width != b.width || a.height != b.height)
        throw InputError("the images differ in size: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                         " and " + std::to_string(b.width) + "x" + std::to_string(b.height));
    CompareReport r;
    r.options = options;
    r.pixels = a.depth.size();
    r.perPixel.assign(r.pixels, PixelComparison::Identical);
    std::vector<std::string> namesA, namesB;
    for (const AovChannel& c : a.extra) namesA.push_back(c.name);
    for (const AovChannel& c : b.extra) namesB.push_back(c.name);
    if (namesA != namesB)
        throw InputError("the images have different secondary-pass channels (shadow.*, ao): rendered with other "
                         "lights or --ao?");
    auto visibilityDiffers = [&](std::size_t i) {
        for (std::size_t c = 0; c < a.extra.size(); ++c)
            if (std::memcmp(&a.extra[c].values[i], &b.extra[c].values[i], sizeof(float)) != 0) return true;
        return false;
    };
    double sumSq = 0.0;
    std::uint64_t bothHit = 0;
    for (std::size_t i = 0; i < a.depth.size(); ++i) {
        if (visibilityDiffers(i)) {
            ++r.differingVisibility;
            r.perPixel[i] = PixelComparison::Differs;
        }
        const bool hitA = a.primId[i] != 0xFFFFFFFFu, hitB = b.primId[i] != 0xFFFFFFFFu;
        const bool samePrim = a.primId[i] == b.primId[i];
        const bool sameDepth = std::memcmp(&a.depth[i], &b.depth[i], sizeof(float)) == 0;
        r.differingPrimId += !samePrim;
        r.differingDepth += !sameDepth;
        r.differingHitMask += hitA != hitB;
        if (samePrim && sameDepth) {
            r.realDifferences += r.perPixel[i] == PixelComparison::Differs;
            continue;
        }
        PixelComparison& kind = r.perPixel[i];
        kind = PixelComparison::Differs;
        if (hitA && hitB) {
            const double rel = relativeDifference(a.depth[i], b.depth[i]);
            ++bothHit;
            sumSq += rel * rel;
            r.maxRelDepthDiff = std::max(r.maxRelDepthDiff, rel);
            const bool visible = !visibilityDiffers(i);
            if (visible && !samePrim && rel <= options.nearTieBound) kind = PixelComparison::NearTie;
            if (visible && samePrim && rel <= options.depthTolerance) kind = PixelComparison::ToleratedDepth;
        }
        r.nearTies += kind == PixelComparison::NearTie;
        r.toleratedDepth += kind == PixelComparison::ToleratedDepth;
        r.realDifferences += kind == PixelComparison::Differs;
    }
    r.rmsRelDepthDiff = bothHit ? std::sqrt(sumSq / double(bothHit)) : 0.0;
    return r;
}

CompareVerdict CompareReport::verdict() const {
    if (realDifferences > 0) return CompareVerdict::Differs;
    return nearTies + toleratedDepth > 0 ? CompareVerdict::NearTiesOnly : CompareVerdict::Identical;
}

std::string CompareReport::verdictLine() const {
    switch (verdict()) {
        case CompareVerdict::Identical: return "compare: identical (" + std::to_string(pixels) + " pixels)";
        case CompareVerdict::NearTiesOnly:
            return "compare: near ties only (" + std::to_string(nearTies) + " near ties, " +
                   std::to_string(toleratedDepth) + " tolerated depths of " + std::to_string(pixels) + " pixels)";
        case CompareVerdict::Differs: break;
    }
    return "compare: differs (" + std::to_string(realDifferences) + " of " + std::to_string(pixels) +
           " pixels beyond near ties and tolerances)";
}

std::string CompareReport::json() const {
    nlohmann::ordered_json j;
    j["verdict"] = toString(verdict());
    j["pixels"] = pixels;
    j["differing_prim_id"] = differingPrimId;
    j["differing_depth"] = differingDepth;
    j["differing_hit_mask"] = differingHitMask;
    j["differing_visibility"] = differingVisibility;
    j["near_ties"] = nearTies;
    j["tolerated_depth"] = toleratedDepth;
    j["real_differences"] = realDifferences;
    j["near_tie_relative_depth_bound"] = options.nearTieBound;
    j["depth_tolerance_relative"] = options.depthTolerance;
    j["max_rel_depth_diff"] = maxRelDepthDiff;
    j["rms_rel_depth_diff"] = rmsRelDepthDiff;
    return j.dump(2);
}

std::string CompareReport::text() const {
    std::ostringstream s;
    s << "pixels              " << pixels << "\n"
      << "differing prim id   " << differingPrimId << "\n"
      << "differing depth     " << differingDepth << " (bitwise)\n"
      << "differing hit mask  " << differingHitMask << "\n"
      << "differing shadow/ao " << differingVisibility << " (secondary-pass channels, bitwise)\n"
      << "near ties           " << nearTies << " (prim id differs, depths within " << options.nearTieBound << " relative)\n"
      << "tolerated depth     " << toleratedDepth << " (same prim id, depths within " << options.depthTolerance
      << " relative)\n"
      << "real differences    " << realDifferences << "\n"
      << "max rel depth diff  " << maxRelDepthDiff << "\n"
      << "rms rel depth diff  " << rmsRelDepthDiff << "\n"
      << verdictLine() << "\n";
    return s.str();
}

std::vector<std::uint8_t> differenceImage(const Aov& a, const CompareReport& report) {
    std::vector<std::uint8_t> rgb(report.perPixel.size() * 3);
    const glm::vec3 light = glm::normalize(glm::vec3(0.3f, 0.5f, 0.8f));
    for (std::size_t i = 0; i < report.perPixel.size(); ++i) {
        glm::vec3 c(0.08f);
        switch (report.perPixel[i]) {
            case PixelComparison::Identical:
                if (a.hit[i] > 0.5f) c = glm::vec3(0.25f + 0.5f * std::abs(glm::dot(a.normal[i], light)));
                break;
            case PixelComparison::NearTie:
            case PixelComparison::ToleratedDepth: c = {1.0f, 0.85f, 0.1f}; break;
            case PixelComparison::Differs: c = {1.0f, 0.1f, 0.1f}; break;
        }
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = std::uint8_t(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255.0f));
    }
    return rgb;
}

}  // namespace dacrt
