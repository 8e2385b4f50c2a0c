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

}  // namespace dacrt
