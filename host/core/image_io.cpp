#include "core/image_io.hpp"
#include "core/shading.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "core/errors.hpp"
#include "core/exr_header.hpp"
#include "core/input_file.hpp"
#include "core/system_memory.hpp"

namespace dacrt {
namespace {

// The file's bytes, encoded in memory by the writer of the path's extension (nothing is written
// at path).
std::string encodePixels(const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc format, const void* data) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw InputError(path + ": cannot write an image here: " + OIIO::geterror());
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput memory(bytes);
    if (!out->set_ioproxy(&memory))
        throw InputError(path + ": OpenImageIO's " + out->format_name() + " writer cannot encode into memory");
    if (!out->open(path, spec) || !out->write_image(format, data) || !out->close())
        throw InputError(path + ": encoding the image failed: " + out->geterror());
    return std::string(bytes.begin(), bytes.end());
}

}  // namespace

std::string imageWriterProblem(const std::string& path) {
    const auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        const std::string why = OIIO::geterror();
        return why.empty() ? "no image writer for this extension" : why;
    }
    if (!out->supports("ioproxy")) return std::string("OpenImageIO's ") + out->format_name() + " writer cannot encode into memory";
    return {};
}

std::string encodeRgb8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
    OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    return encodePixels(path, spec, OIIO::TypeDesc::UINT8, rgb.data());
}

std::string encodeAov(const std::string& path, const Scene& scene, const HitImage& image, const std::vector<AovChannel>& extra) {
    struct Pixel {
        float z, nx, ny, nz;
        std::uint32_t primId;
        float hit, u, v;
        float albedoR, albedoG, albedoB;
    };
    std::vector<Pixel> pixels(image.hits->size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const Hit& h = (*image.hits)[i];
        Pixel& p = pixels[i];
        if (h.prim == kMissPrim) {
            p = Pixel{std::numeric_limits<float>::infinity(), 0, 0, 0, kMissPrim, 0, 0, 0, 0, 0, 0};
        } else {
            const glm::vec3 n = geometricNormal(scene.triangles[h.prim]);
            const glm::vec3 albedo = surfaceAt(scene, h).albedo;
            p = Pixel{h.t, n.x, n.y, n.z, h.prim, 1.0f, h.u, h.v, albedo.r, albedo.g, albedo.b};
        }
    }
    // Native per-channel formats, pixel by pixel: the fixed channels, then the extra ones.
    const std::size_t stride = sizeof(Pixel) + extra.size() * sizeof(float);
    std::vector<unsigned char> packed(pixels.size() * stride);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        std::memcpy(&packed[i * stride], &pixels[i], sizeof(Pixel));
        for (std::size_t c = 0; c < extra.size(); ++c)
            std::memcpy(&packed[i * stride + sizeof(Pixel) + c * sizeof(float)], &extra[c].values.at(i), sizeof(float));
    }
    const int channels = 11 + int(extra.size());
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v", "albedo.R", "albedo.G", "albedo.B"};
    for (const AovChannel& c : extra) spec.channelnames.push_back(c.name);
    spec.channelformats.assign(std::size_t(channels), OIIO::TypeDesc::FLOAT);
    spec.channelformats[4] = OIIO::TypeDesc::UINT32;
    spec.z_channel = 0;
    spec.attribute("compression", "zip");
    // OpenImageIO stamps the write's wall-clock time (OpenEXR's capDate) when none is given;
    // a fixed one keeps the same frame's file identical bit for bit across runs and shards.
    spec.attribute("DateTime", "1970:01:01 00:00:00");
    return encodePixels(path, spec, OIIO::TypeDesc::UNKNOWN, packed.data());
}

Aov readAov(const std::string& path, std::uint64_t maxBytes) {
    const std::uint64_t fileSize = regularInputSize(path, 0);  // OpenImageIO would wait on a FIFO or read a device without end
    checkExrHeaderSizes(path, fileSize);
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw InputError(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    // The header's data window is the file's word, not a fact: a few bytes may declare an image
    // of terabytes. dacrt writes at most 16384 x 16384 pixels (render --size).
    if (spec.width < 1 || spec.height < 1 || spec.width > 16384 || spec.height > 16384 || spec.nchannels < 1 ||
        spec.nchannels > 1024)
        throw InputError(path + ": the header declares " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " pixels of " + std::to_string(spec.nchannels) +
                         " channels; dacrt's AOVs have 1..16384 pixels a side and at most 1024 channels");
    const std::uint64_t needed = std::uint64_t(spec.width) * std::uint64_t(spec.height) * (12 + std::uint64_t(spec.nchannels)) * 4;
    if (const std::uint64_t memory = maxBytes ? maxBytes : physicalMemoryBytes(); memory && needed > memory)
        throw InputError(path + ": reading its " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " pixels needs " + std::to_string(needed) + " bytes, more than " +
                         (maxBytes ? "the limit of " : "this machine's ") + std::to_string(memory) + " bytes" +
                         (maxBytes ? std::string() : std::string(" of memory")));
    Aov aov;
    aov.width = spec.width;
    aov.height = spec.height;
    const std::size_t n = std::size_t(spec.width) * std::size_t(spec.height);
    auto channel = [&](const char* name) {
        const int c = spec.channelindex(name);
        if (c < 0) throw InputError(path + ": no '" + name + "' channel; is it an AOV file written by dacrt?");
        return c;
    };
    aov.depth.resize(n);
    aov.normal.resize(n);
    aov.primId.resize(n);
    aov.hit.resize(n);
    const int z = channel("Z"), prim = channel("primId"), hit = channel("hit"), nx = channel("N.X");
    if (channel("N.Y") != nx + 1 || channel("N.Z") != nx + 2)
        throw InputError(path + ": the N.X, N.Y and N.Z channels are not consecutive");
    if (spec.channelformat(prim) != OIIO::TypeDesc::UINT32)
        throw InputError(path + ": the primId channel is not unsigned 32-bit");
    if (!in->read_image(0, 0, z, z + 1, OIIO::TypeDesc::FLOAT, aov.depth.data()) ||
        !in->read_image(0, 0, nx, nx + 3, OIIO::TypeDesc::FLOAT, aov.normal.data()) ||
        !in->read_image(0, 0, prim, prim + 1, OIIO::TypeDesc::UINT32, aov.primId.data()) ||
        !in->read_image(0, 0, hit, hit + 1, OIIO::TypeDesc::FLOAT, aov.hit.data()))
        throw InputError(path + ": reading failed: " + in->geterror());
    if (const int albedo = spec.channelindex("albedo.R"); albedo >= 0) {
        if (spec.channelindex("albedo.G") != albedo + 1 || spec.channelindex("albedo.B") != albedo + 2)
            throw InputError(path + ": the albedo.R, albedo.G and albedo.B channels are not consecutive");
        aov.albedo.resize(n);
        if (!in->read_image(0, 0, albedo, albedo + 3, OIIO::TypeDesc::FLOAT, aov.albedo.data()))
            throw InputError(path + ": reading failed: " + in->geterror());
    }
    static const std::vector<std::string> fixed = {"Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v",
                                                   "albedo.R", "albedo.G", "albedo.B"};
    for (int c = 0; c < spec.nchannels; ++c) {
        const std::string& name = spec.channelnames[std::size_t(c)];
        if (std::find(fixed.begin(), fixed.end(), name) != fixed.end()) continue;
        AovChannel extra{name, std::vector<float>(n)};
        if (!in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::FLOAT, extra.values.data()))
            throw InputError(path + ": reading failed: " + in->geterror());
        aov.extra.push_back(std::move(extra));
    }
    return aov;
}

}  // namespace dacrt
