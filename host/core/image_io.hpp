#pragma once
// The write stage (shaded PNG, AOV EXR) and AOVs read back, through OpenImageIO.
#include <cstdint>
#include <string>
#include <vector>

#include "core/hit_image.hpp"
#include "core/scene.hpp"

namespace dacrt {

// Empty when OpenImageIO has a writer for the path's extension that can encode into memory,
// else why not.
std::string imageWriterProblem(const std::string& path);

// Images are encoded into memory and their bytes written by an OutputBatch
// (core/atomic_file.hpp), which checks every step of the write: OpenImageIO's own file
// writing reports no error for some formats on a full disk.

// An 8-bit RGB image, row-major, in the format OpenImageIO writes for the path's extension.
std::string encodeRgb8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

// Multi-channel EXR: Z (ray parameter t, +inf on a miss; directions are unit length),
// N.X N.Y N.Z (unit geometric normal), primId (exact uint32, 0xFFFFFFFF on a miss),
// hit (1 or 0), u v (barycentric weights of the second and third vertex), albedo.R albedo.G
// albedo.B (linear base colour: factor x texture x vertex colour; 0 on a miss).
// Then `extra` float channels, one value per pixel each (the secondary passes' visibility).
struct AovChannel {
    std::string name;
    std::vector<float> values;
};
// The AOVs as an OpenEXR file's bytes.
std::string encodeAov(const std::string& path, const Scene& scene, const HitImage& image,
                      const std::vector<AovChannel>& extra = {});

struct Aov {
    int width = 0;
    int height = 0;
    std::vector<float> depth;
    std::vector<glm::vec3> normal;
    std::vector<std::uint32_t> primId;
    std::vector<float> hit;
    std::vector<glm::vec3> albedo;  // empty when the file has no albedo channels
    std::vector<AovChannel> extra;  // the float channels after albedo.B, in the file's order
};

// Reads an AOV written by encodeAov; throws InputError on a missing file, a non-image,
// missing channels, or a header whose pixels need more than `maxBytes` to read (0: this
// machine's memory).
Aov readAov(const std::string& path, std::uint64_t maxBytes = 0);

}  // namespace dacrt
