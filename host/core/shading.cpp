#include "core/shading.hpp"

#include <algorithm>
#include <cmath>

namespace dacrt {
namespace {

std::uint8_t srgb8(float linear) {
    const float c = std::clamp(linear, 0.0f, 1.0f);
    const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(s * 255.0f));
}

}  // namespace

std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image) {
    const glm::vec3 background(0.18f, 0.20f, 0.24f);
    std::vector<std::uint8_t> rgb(std::size_t(image.width) * std::size_t(image.height) * 3);
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const Hit& h = (*image.hits)[i];
        glm::vec3 c = background;
        if (h.prim != kMissPrim) {
            const glm::vec3 n = geometricNormal(scene.triangles[h.prim]);
            const float cosine = std::abs(glm::dot(n, (*image.rays)[i].dir));
            const glm::vec4 base = scene.materials[scene.materialOfTriangle[h.prim]].baseColor;
            c = glm::vec3(base) * (0.12f + 0.88f * cosine);
        }
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = srgb8(c[k]);
    }
    return rgb;
}

}  // namespace dacrt
