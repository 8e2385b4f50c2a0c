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

// Headlight Lambert (|cos| between ray and shading normal) times the albedo, sRGB encoded to
// 8-bit RGB, row-major; misses get a fixed background.
std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image);

// The same in linear RGB, for averaging samples: adds each pixel's colour times `weight` to
// `sum`.
void accumulateShading(const Scene& scene, const HitImage& image, float weight, std::vector<glm::vec3>& sum);

// Linear RGB to 8-bit sRGB.
std::vector<std::uint8_t> encodeSrgb8(const std::vector<glm::vec3>& linear);

// Viewable pictures of the AOVs: depth (near bright, far dark, misses black, scaled between the
// image's nearest and farthest hit) and normals (n * 0.5 + 0.5; misses black).
std::vector<std::uint8_t> depthPreview(const HitImage& image);
std::vector<std::uint8_t> normalPreview(const Scene& scene, const HitImage& image);

}  // namespace dacrt
