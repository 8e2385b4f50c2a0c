#pragma once
// Images out (shaded PNG, AOV EXR) and AOVs back in, through OpenImageIO.
#include <cstdint>
#include <string>
#include <vector>

#include "scene.hpp"

namespace dacrt {

struct HitImage {
    int width = 0;
    int height = 0;
    const std::vector<Ray>* rays = nullptr;
    const std::vector<Hit>* hits = nullptr;
};

// Headlight Lambert (|cos| between ray and geometric normal) times the base colour, sRGB
// encoded to 8-bit RGB; misses get a fixed background.
std::vector<std::uint8_t> shadeImage(const Scene& scene, const HitImage& image);

// Headlight Lambert (|cos| between ray and geometric normal) times the base colour, sRGB
// encoded; misses get a fixed background. Any format OpenImageIO writes from the extension.
void writeShaded(const std::string& path, const Scene& scene, const HitImage& image);

// Multi-channel EXR: Z (ray parameter t, +inf on a miss; directions are unit length),
// N.X N.Y N.Z (unit geometric normal), primId (exact uint32, 0xFFFFFFFF on a miss),
// hit (1 or 0), u v (barycentric weights of the second and third vertex).
void writeAov(const std::string& path, const Scene& scene, const HitImage& image);

struct Aov {
    int width = 0;
    int height = 0;
    std::vector<float> depth;
    std::vector<std::uint32_t> primId;
    std::vector<float> hit;
};

// Reads an AOV written by writeAov; throws InputError on a missing file, a non-image, or
// missing channels.
Aov readAov(const std::string& path);

}  // namespace dacrt
