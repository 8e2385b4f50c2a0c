#include "stress/stress_cases.hpp"

#include <algorithm>

#include "stress/case_building.hpp"
#include "core/errors.hpp"

namespace dacrt {

std::size_t StressCase::mustHitCount() const {
    return std::size_t(std::count(mustHit.begin(), mustHit.end(), std::uint8_t(1)));
}

std::vector<std::string> stressFamilies() { return {"watertight", "split-plane", "degenerate", "surface-rays"}; }

StressCase determinismCase(StressSize size) {
    StressCase c{"determinism", "room with shapes from the centre", stress::trianglesOf(stress::roomWithShapes()), {}, {}, {}};
    stress::RayFan fan(c, glm::vec3(0.0f), true);
    const bool large = size == StressSize::Large;
    stress::addPinhole(fan, glm::normalize(glm::dvec3(0.3, -0.2, -1.0)), {0, 1, 0}, large ? 321 : 121, large ? 241 : 91);
    return c;
}

std::vector<StressCase> stressCases(const std::vector<std::string>& families, StressSize size, std::uint64_t seed) {
    std::vector<StressCase> out;
    for (const std::string& f : families) {
        std::vector<StressCase> part;
        if (f == "watertight") part = watertightCases(size, seed);
        else if (f == "split-plane") part = splitPlaneCases(size, seed);
        else if (f == "degenerate") part = degenerateCases(size, seed);
        else if (f == "surface-rays") part = surfaceCases(size, seed);
        else
            throw InputError("stress: unknown family '" + f +
                             "' (choose from watertight, split-plane, degenerate, surface-rays)");
        for (StressCase& c : part) out.push_back(std::move(c));
    }
    return out;
}

}  // namespace dacrt
