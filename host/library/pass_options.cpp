#include "library/pass_options.hpp"

#include <cmath>

#include "core/errors.hpp"
#include "library/frame_passes.hpp"

namespace dacrt {

void checkPassOptions(const PassOptions& o) {
    for (const std::string& light : o.lights) parseLightSpec(light);
    if (o.occlusionSamples > 1024) throw InputError("--ao " + std::to_string(o.occlusionSamples) + ": at most 1024 rays per hit");
    if (!std::isfinite(o.occlusionDistance) || o.occlusionDistance < 0.0 || o.occlusionDistance > kMaxCoordinate ||
        (o.occlusionDistance > 0.0 && o.occlusionDistance < 1e-30))
        throw InputError("--ao-distance must be a length from 1e-30 to " + std::to_string(kMaxCoordinate) +
                         " (0: a tenth of the scene's diagonal)");
}

float occlusionDistance(const PassOptions& o, const Box& box) {
    if (o.occlusionDistance > 0.0) return float(o.occlusionDistance);
    return float(0.1 * glm::length(glm::dvec3(box.extent())));
}

std::vector<FramePass> framePasses(const std::vector<Light>& lights, const PassOptions& o, const Box& box,
                                   std::uint32_t seed) {
    std::vector<FramePass> passes;
    for (const SecondaryPass& pass : secondaryPasses(lights, o, box, seed)) passes.push_back(framePassOf(pass));
    return passes;
}

}  // namespace dacrt
