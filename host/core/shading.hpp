#pragma once
// The shade stage: hits to an 8-bit sRGB preview.
#include <cstdint>
#include <vector>

#include "core/hit_image.hpp"
#include "core/scene.hpp"

namespace dacrt {

// Headlight Lambert (|cos| between ray and geometric normal) times the base colour, sRGB
// encoded to 8-bit RGB, row-major; misses get a fixed background.
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
