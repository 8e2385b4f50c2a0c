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

namespace {

glm::vec3 shadePixel(const Scene& scene, const HitImage& image, std::size_t i) {
    const glm::vec3 background(0.18f, 0.20f, 0.24f);
    const Hit& h = (*image.hits)[i];
    if (h.prim == kMissPrim) return background;
    const glm::vec3 n = geometricNormal(scene.triangles[h.prim]);
    const float cosine = std::abs(glm::dot(n, (*image.rays)[i].dir));
    const glm::vec4 base = scene.materials[scene.materialOfTriangle[h.prim]].baseColor;
    return glm::vec3(base) * (0.12f + 0.88f * cosine);
}

std::uint8_t unorm8(float v) { return std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

}  // namespace

std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image) {
    std::vector<std::uint8_t> rgb(std::size_t(image.width) * std::size_t(image.height) * 3);
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const glm::vec3 c = shadePixel(scene, image, i);
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = srgb8(c[k]);
    }
    return rgb;
}

void accumulateShading(const Scene& scene, const HitImage& image, float weight, std::vector<glm::vec3>& sum) {
    sum.resize(image.hits->size(), glm::vec3(0.0f));
    for (std::size_t i = 0; i < image.hits->size(); ++i) sum[i] += weight * shadePixel(scene, image, i);
}

std::vector<std::uint8_t> encodeSrgb8(const std::vector<glm::vec3>& linear) {
    std::vector<std::uint8_t> rgb(linear.size() * 3);
    for (std::size_t i = 0; i < linear.size(); ++i)
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = srgb8(linear[i][k]);
    return rgb;
}

std::vector<std::uint8_t> depthPreview(const HitImage& image) {
    float nearest = kNoHitT, farthest = 0.0f;
    for (const Hit& h : *image.hits)
        if (h.prim != kMissPrim) nearest = std::min(nearest, h.t), farthest = std::max(farthest, h.t);
    std::vector<std::uint8_t> rgb(image.hits->size() * 3, 0);
    const float span = farthest > nearest ? farthest - nearest : 1.0f;
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const Hit& h = (*image.hits)[i];
        if (h.prim == kMissPrim) continue;
        const std::uint8_t v = unorm8(1.0f - 0.85f * (h.t - nearest) / span);
        rgb[i * 3] = rgb[i * 3 + 1] = rgb[i * 3 + 2] = v;
    }
    return rgb;
}

std::vector<std::uint8_t> normalPreview(const Scene& scene, const HitImage& image) {
    std::vector<std::uint8_t> rgb(image.hits->size() * 3, 0);
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const Hit& h = (*image.hits)[i];
        if (h.prim == kMissPrim) continue;
        const glm::vec3 n = geometricNormal(scene.triangles[h.prim]) * 0.5f + 0.5f;
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = unorm8(n[k]);
    }
    return rgb;
}

}  // namespace dacrt
