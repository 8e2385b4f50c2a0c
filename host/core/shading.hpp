#pragma once
// The shade stage: hits to an 8-bit sRGB preview.
#include <cstdint>
#include <vector>

#include "core/hit_image.hpp"
#include "core/scene.hpp"

namespace dacrt {

// The surface at a hit as the preview shades it: the material's base colour factor times its
// base colour texture times the vertex colour (linear RGB), and the normal interpolated from
// the corners' NORMAL (the geometric normal where the primitive has none).
struct SurfacePoint {
    glm::vec3 albedo{1.0f};
    glm::vec3 normal{0.0f, 0.0f, 1.0f};
};
SurfacePoint surfaceAt(const Scene& scene, const Hit& hit);

// What the secondary passes found, slot by slot (as hitsPerSlot gives them), for the lit
// shading: per light, one slot per pixel (kMissPrim: lit, kNotTracedPrim: the light cannot
// reach the surface, anything else: shadowed); for occlusion, `occlusionSamples` slots per
// pixel (kMissPrim: open). No lights: the headlight preview, times the occlusion if any.
struct Lighting {
    std::vector<const Light*> lights;
    std::vector<const std::vector<Hit>*> shadows;     // one per light
    const std::vector<Hit>* occlusion = nullptr;
    std::uint32_t occlusionSamples = 0;
    float exposure = 1.0f;                            // autoExposure
};

// The illuminance a light gives a surface point with unit normal n, times its colour and the
// cosine, unshadowed: glTF's units (candela, lux), its range and spot cone falloffs.
glm::dvec3 illuminance(const Light& light, const glm::dvec3& point, const glm::dvec3& normal);

// The scale that brings the 90th percentile of the lit pixels' unshadowed direct light to 0.6
// (0.8 with the ambient term):
// physical light units of any size give a viewable image, and the same primary hits give the
// same scale whatever traced the shadows.
float autoExposure(const Scene& scene, const HitImage& image, const std::vector<const Light*>& lights);

// Lambert times the albedo, sRGB encoded to 8-bit RGB, row-major; misses get a fixed
// background. Without lighting (or with no lights in it): a headlight (|cos| between ray and
// shading normal). With lights: an ambient term times the open fraction of the occlusion rays
// (1 without them) plus each light's illuminance where its shadow ray found nothing.
std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image, const Lighting* lighting = nullptr);

// The same in linear RGB, for averaging samples: adds each pixel's colour times `weight` to
// `sum`.
void accumulateShading(const Scene& scene, const HitImage& image, float weight, std::vector<glm::vec3>& sum,
                       const Lighting* lighting = nullptr);

// The open fraction of a pixel's occlusion rays, and whether light k reaches it unshadowed.
float openFraction(const Lighting& lighting, std::size_t pixel);
bool litBy(const Lighting& lighting, std::size_t light, std::size_t pixel);

// Linear RGB to 8-bit sRGB.
std::vector<std::uint8_t> encodeSrgb8(const std::vector<glm::vec3>& linear);

// Viewable pictures of the AOVs: depth (near bright, far dark, misses black, scaled between the
// image's nearest and farthest hit) and normals (n * 0.5 + 0.5; misses black).
std::vector<std::uint8_t> depthPreview(const HitImage& image);
std::vector<std::uint8_t> normalPreview(const Scene& scene, const HitImage& image);

}  // namespace dacrt
