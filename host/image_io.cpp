#include "image_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <OpenImageIO/imageio.h>

#include "errors.hpp"

namespace dacrt {
namespace {

glm::vec3 geometricNormal(const Triangle& t) {
    const glm::dvec3 n = glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0));
    const double len = glm::length(n);
    return len > 0.0 ? glm::vec3(n / len) : glm::vec3(0.0f);
}

std::uint8_t srgb8(float linear) {
    const float c = std::clamp(linear, 0.0f, 1.0f);
    const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(s * 255.0f));
}

void writePixels(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc format, const void* data) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(path + ": cannot write an image here: " + OIIO::geterror());
    if (!out->open(path, spec) || !out->write_image(format, data) || !out->close())
        throw InputError(path + ": writing failed: " + out->geterror());
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

void writeShaded(const std::string& path, const Scene& scene, const HitImage& image) {
    const std::vector<std::uint8_t> rgb = shadeImage(scene, image);
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
    writePixels(path, spec, OIIO::TypeDesc::UINT8, rgb.data());
}

void writeAov(const std::string& path, const Scene& scene, const HitImage& image) {
    struct Pixel {
        float z, nx, ny, nz;
        std::uint32_t primId;
        float hit, u, v;
    };
    std::vector<Pixel> pixels(image.hits->size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const Hit& h = (*image.hits)[i];
        Pixel& p = pixels[i];
        if (h.prim == kMissPrim) {
            p = Pixel{std::numeric_limits<float>::infinity(), 0, 0, 0, kMissPrim, 0, 0, 0};
        } else {
            const glm::vec3 n = geometricNormal(scene.triangles[h.prim]);
            p = Pixel{h.t, n.x, n.y, n.z, h.prim, 1.0f, h.u, h.v};
        }
    }
    OIIO::ImageSpec spec(image.width, image.height, 8, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v"};
    spec.channelformats.assign(8, OIIO::TypeDesc::FLOAT);
    spec.channelformats[4] = OIIO::TypeDesc::UINT32;
    spec.z_channel = 0;
    spec.attribute("compression", "zip");
    writePixels(path, spec, OIIO::TypeDesc::UNKNOWN, pixels.data());
}

Aov readAov(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw InputError(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Aov aov;
    aov.width = spec.width;
    aov.height = spec.height;
    const std::size_t n = std::size_t(spec.width) * std::size_t(spec.height);
    auto channel = [&](const char* name) {
        const int c = spec.channelindex(name);
        if (c < 0) throw InputError(path + ": no '" + name + "' channel; is it a dacrt --aov file?");
        return c;
    };
    aov.depth.resize(n);
    aov.primId.resize(n);
    aov.hit.resize(n);
    const int z = channel("Z"), prim = channel("primId"), hit = channel("hit");
    if (spec.channelformat(prim) != OIIO::TypeDesc::UINT32)
        throw InputError(path + ": the primId channel is not unsigned 32-bit");
    if (!in->read_image(0, 0, z, z + 1, OIIO::TypeDesc::FLOAT, aov.depth.data()) ||
        !in->read_image(0, 0, prim, prim + 1, OIIO::TypeDesc::UINT32, aov.primId.data()) ||
        !in->read_image(0, 0, hit, hit + 1, OIIO::TypeDesc::FLOAT, aov.hit.data()))
        throw InputError(path + ": reading failed: " + in->geterror());
    return aov;
}

}  // namespace dacrt
