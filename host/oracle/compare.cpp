#include "oracle/compare.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace dacrt {

CompareReport compareAovs(const Aov& a, const Aov& b, double bound) {
    if (a.width != b.width || a.height != b.height)
        throw InputError("the images differ in size: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                         " and " + std::to_string(b.width) + "x" + std::to_string(b.height));
    CompareReport r;
    r.nearTieBound = bound;
    r.pixels = a.depth.size();
    double sumSq = 0.0;
    std::uint64_t bothHit = 0;
    for (std::size_t i = 0; i < a.depth.size(); ++i) {
        const bool hitA = a.primId[i] != 0xFFFFFFFFu, hitB = b.primId[i] != 0xFFFFFFFFu;
        const bool samePrim = a.primId[i] == b.primId[i];
        if (!samePrim) ++r.differingPrimId;
        if (std::memcmp(&a.depth[i], &b.depth[i], sizeof(float)) != 0) ++r.differingDepth;
        if (hitA != hitB) ++r.differingHitMask;
        if (!(hitA && hitB)) continue;
        const double da = a.depth[i], db = b.depth[i];
        const double rel = std::abs(da - db) / std::max(std::abs(da), std::abs(db));
        const double relSafe = std::isfinite(rel) ? rel : 0.0;
        ++bothHit;
        sumSq += relSafe * relSafe;
        r.maxRelDepthDiff = std::max(r.maxRelDepthDiff, relSafe);
        if (!samePrim && relSafe <= bound) ++r.nearTies;
    }
    r.rmsRelDepthDiff = bothHit ? std::sqrt(sumSq / double(bothHit)) : 0.0;
    return r;
}

std::string CompareReport::json() const {
    nlohmann::ordered_json j;
    j["pixels"] = pixels;
    j["differing_prim_id"] = differingPrimId;
    j["differing_depth"] = differingDepth;
    j["differing_hit_mask"] = differingHitMask;
    j["near_ties"] = nearTies;
    j["near_tie_relative_depth_bound"] = nearTieBound;
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
      << "near ties           " << nearTies << " (prim id differs, depths within " << nearTieBound << " relative)\n"
      << "max rel depth diff  " << maxRelDepthDiff << "\n"
      << "rms rel depth diff  " << rmsRelDepthDiff << "\n";
    return s.str();
}

}  // namespace dacrt
