#pragma once
// Portable random numbers for generated scenes and tests: std::mt19937_64's sequence is fixed
// by the standard, but the standard distributions and std::shuffle differ between standard
// libraries, so the same seed would give other cases elsewhere.
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace dacrt {

class Random {
public:
    explicit Random(std::uint64_t seed) : engine_(seed) {}
    // Uniform in [0, 1) with 53 random bits.
    double uniform() { return double(engine_() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    float uniformFloat(float lo, float hi) { return float(uniform(lo, hi)); }
    // Uniform in [0, n) for n > 0.
    std::size_t index(std::size_t n) { return std::min(std::size_t(uniform() * double(n)), n - 1); }
    // Braced lists are evaluated left to right, so these draw x, y, z in that order.
    glm::dvec3 inBox(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }
    glm::vec3 vec3(float lo, float hi) { return {uniformFloat(lo, hi), uniformFloat(lo, hi), uniformFloat(lo, hi)}; }
    glm::dvec3 onSphere() {
        for (;;) {
            const glm::dvec3 p = inBox(-1.0, 1.0);
            const double l = glm::length(p);
            if (l > 1e-3 && l <= 1.0) return p / l;
        }
    }
    // Fisher-Yates.
    template <typename T>
    void shuffle(std::vector<T>& v) {
        for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[index(i)]);
    }

private:
    std::mt19937_64 engine_;
};

}  // namespace dacrt
