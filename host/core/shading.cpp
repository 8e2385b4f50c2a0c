#include "core/shading.hpp"

#include <algorithm>
#include <cmath>

#include "core/texture_sampling.hpp"

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
    const SurfacePoint s = surfaceAt(scene, h);
    const float cosine = std::abs(glm::dot(s.normal, (*image.rays)[i].dir));
    return s.albedo * (0.12f + 0.88f * cosine);
}

std::uint8_t unorm8(float v) { return std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

}  // namespace

SurfacePoint surfaceAt(const Scene& scene, const Hit& h) {
    SurfacePoint s;
    const float w[3] = {1.0f - h.u - h.v, h.u, h.v};
    const Material& material = scene.materials[scene.materialOfTriangle[h.prim]];
    glm::vec4 albedo = material.baseColor;
    const CornerAttributes& c = scene.corners;
    if (!c.colors.empty()) albedo *= w[0] * c.colors[h.prim][0] + w[1] * c.colors[h.prim][1] + w[2] * c.colors[h.prim][2];
    const TextureBinding& binding = material.baseColorTexture;
    if (binding.texture >= 0) {
        const glm::vec2 uv = c.texCoords.empty() ? glm::vec2(0.0f)
                                                 : w[0] * c.texCoords[h.prim][0] + w[1] * c.texCoords[h.prim][1] +
                                                       w[2] * c.texCoords[h.prim][2];
        albedo *= sampleTexture(scene.textures[std::size_t(binding.texture)], binding, uv);
    }
    s.albedo = glm::vec3(albedo);
    s.normal = geometricNormal(scene.triangles[h.prim]);
    if (!c.normals.empty()) {
        const std::array<glm::vec3, 3>& n = c.normals[h.prim];
        const glm::vec3 smooth = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
        const float length = glm::length(smooth);
        if (length > 1e-12f && std::isfinite(length)) s.normal = smooth / length;
    }
    return s;
}

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
