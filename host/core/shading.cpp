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

// Light in display units on a surface facing the sky: what the shadowed side keeps.
constexpr float kAmbient = 0.2f;

glm::vec3 headlightPixel(const SurfacePoint& s, const Ray& ray) {
    const float cosine = std::abs(glm::dot(s.normal, ray.dir));
    return s.albedo * (0.12f + 0.88f * cosine);
}

glm::dvec3 hitPoint(const Scene& scene, const Hit& h) {
    const Triangle& t = scene.triangles[h.prim];
    const double u = h.u, v = h.v;
    return (1.0 - u - v) * glm::dvec3(t.v0) + u * glm::dvec3(t.v1) + v * glm::dvec3(t.v2);
}

// The shading normal turned towards the ray's origin (a double-sided surface seen from behind).
glm::dvec3 facingNormal(const SurfacePoint& s, const Ray& ray) {
    const glm::dvec3 n(s.normal);
    return glm::dot(n, glm::dvec3(ray.dir)) > 0.0 ? -n : n;
}

glm::vec3 shadePixel(const Scene& scene, const HitImage& image, std::size_t i, const Lighting* lighting) {
    const glm::vec3 background(0.18f, 0.20f, 0.24f);
    const Hit& h = (*image.hits)[i];
    if (h.prim == kMissPrim) return background;
    const SurfacePoint s = surfaceAt(scene, h);
    const Ray& ray = (*image.rays)[i];
    if (!lighting) return headlightPixel(s, ray);
    const float open = openFraction(*lighting, i);
    if (lighting->lights.empty()) return headlightPixel(s, ray) * open;
    glm::dvec3 direct(0.0);
    const glm::dvec3 point = hitPoint(scene, h), normal = facingNormal(s, ray);
    for (std::size_t k = 0; k < lighting->lights.size(); ++k)
        if (litBy(*lighting, k, i)) direct += illuminance(*lighting->lights[k], point, normal);
    return s.albedo * (kAmbient * open + lighting->exposure * glm::vec3(direct));
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

float openFraction(const Lighting& lighting, std::size_t pixel) {
    if (!lighting.occlusion || lighting.occlusionSamples == 0) return 1.0f;
    std::uint32_t open = 0;
    for (std::uint32_t k = 0; k < lighting.occlusionSamples; ++k)
        open += (*lighting.occlusion)[pixel * lighting.occlusionSamples + k].prim == kMissPrim;
    return float(open) / float(lighting.occlusionSamples);
}

bool litBy(const Lighting& lighting, std::size_t light, std::size_t pixel) {
    return (*lighting.shadows[light])[pixel].prim == kMissPrim;
}

glm::dvec3 illuminance(const Light& light, const glm::dvec3& point, const glm::dvec3& normal) {
    glm::dvec3 toLight = -light.direction;
    double amount = light.intensity;
    if (light.type != LightType::Directional) {
        toLight = light.position - point;
        const double distance = glm::length(toLight);
        if (distance == 0.0) return glm::dvec3(0.0);
        toLight /= distance;
        double falloff = 1.0 / (distance * distance);
        if (light.range > 0.0f) falloff *= std::clamp(1.0 - std::pow(distance / light.range, 4.0), 0.0, 1.0);
        if (light.type == LightType::Spot) {
            // KHR_lights_punctual's recommended cone falloff, squared.
            const double cosOuter = std::cos(light.outerConeAngle), cosInner = std::cos(light.innerConeAngle);
            const double scale = 1.0 / std::max(0.001, cosInner - cosOuter);
            const double cone = std::clamp((glm::dot(light.direction, -toLight) - cosOuter) * scale, 0.0, 1.0);
            falloff *= cone * cone;
        }
        amount *= falloff;
    }
    return glm::dvec3(light.color) * amount * std::max(0.0, glm::dot(normal, toLight));
}

float autoExposure(const Scene& scene, const HitImage& image, const std::vector<const Light*>& lights) {
    std::vector<double> lit;
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const Hit& h = (*image.hits)[i];
        if (h.prim == kMissPrim) continue;
        const SurfacePoint s = surfaceAt(scene, h);
        const glm::dvec3 point = hitPoint(scene, h), normal = facingNormal(s, (*image.rays)[i]);
        glm::dvec3 direct(0.0);
        for (const Light* light : lights) direct += illuminance(*light, point, normal);
        const double luminance = 0.2126 * direct.r + 0.7152 * direct.g + 0.0722 * direct.b;
        if (luminance > 0.0) lit.push_back(luminance);
    }
    if (lit.empty()) return 1.0f;
    const std::size_t k = lit.size() * 9 / 10;
    std::nth_element(lit.begin(), lit.begin() + std::ptrdiff_t(k), lit.end());
    return float(0.6 / lit[k]);
}

std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image, const Lighting* lighting) {
    std::vector<std::uint8_t> rgb(std::size_t(image.width) * std::size_t(image.height) * 3);
    for (std::size_t i = 0; i < image.hits->size(); ++i) {
        const glm::vec3 c = shadePixel(scene, image, i, lighting);
        for (int k = 0; k < 3; ++k) rgb[i * 3 + std::size_t(k)] = srgb8(c[k]);
    }
    return rgb;
}

void accumulateShading(const Scene& scene, const HitImage& image, float weight, std::vector<glm::vec3>& sum,
                       const Lighting* lighting) {
    sum.resize(image.hits->size(), glm::vec3(0.0f));
    for (std::size_t i = 0; i < image.hits->size(); ++i) sum[i] += weight * shadePixel(scene, image, i, lighting);
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
