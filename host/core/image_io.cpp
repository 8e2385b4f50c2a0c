#include "core/image_io.hpp"
#include "core/shading.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/errors.hpp"
#include "core/exr_header.hpp"
#include "core/image_codecs.hpp"
#include "core/input_file.hpp"
#include "core/system_memory.hpp"

namespace dacrt {
namespace {

// The file's bytes, encoded in memory by the writer of the path's extension (nothing is written
// at path).
std::string encodePixels(const std::string& path, const ImageToEncode& image) {
    std::string bytes;
    if (std::string error = imageCodecs().encode(path, image, bytes); !error.empty()) throw InputError(error);
    return bytes;
}

}  // namespace

std::string imageWriterProblem(const std::string& path) { return imageCodecs().writerProblem(path); }

std::string encodeRgb8(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb) {
    ImageToEncode image;
    image.width = width;
    image.height = height;
    image.channelNames = {"R", "G", "B"};
    image.channelTypes.assign(3, SampleType::UInt8);
    image.pixels = rgb.data();
    return encodePixels(path, image);
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
    ImageToEncode aov;
    aov.width = image.width;
    aov.height = image.height;
    aov.channelNames = {"Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v", "albedo.R", "albedo.G", "albedo.B"};
    for (const AovChannel& c : extra) aov.channelNames.push_back(c.name);
    aov.channelTypes.assign(aov.channelNames.size(), SampleType::Float);
    aov.channelTypes[4] = SampleType::UInt32;
    aov.depthChannel = 0;
    // OpenImageIO stamps the write's wall-clock time (OpenEXR's capDate) when none is given;
    // a fixed one keeps the same frame's file identical bit for bit across runs and shards.
    aov.attributes = {{"compression", "zip"}, {"DateTime", "1970:01:01 00:00:00"}};
    aov.pixels = packed.data();
    return encodePixels(path, aov);
}

Aov readAov(const std::string& path, std::uint64_t maxBytes) {
    const std::uint64_t fileSize = regularInputSize(path, 0);  // OpenImageIO would wait on a FIFO or read a device without end
    checkExrHeaderSizes(path, fileSize);
    std::string openError;
    const std::unique_ptr<ImageReader> in = imageCodecs().openFile(path, openError);
    if (!in) throw InputError(path + ": cannot read image: " + openError);
    const ImageHeader& spec = in->header();
    const int channelCount = int(spec.channelNames.size());
    // The header's data window is the file's word, not a fact: a few bytes may declare an image
    // of terabytes. dacrt writes at most 16384 x 16384 pixels (render --size).
    if (spec.width < 1 || spec.height < 1 || spec.width > 16384 || spec.height > 16384 || channelCount < 1 ||
        channelCount > 1024)
        throw InputError(path + ": the header declares " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                         " pixels of " + std::to_string(channelCount) +
                         " channels; dacrt's AOVs have 1..16384 pixels a side and at most 1024 channels");
    const std::uint64_t needed = std::uint64_t(spec.width) * std::uint64_t(spec.height) * (12 + std::uint64_t(channelCount)) * 4;
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
        const int c = spec.channelIndex(name);
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
    if (spec.channelTypes[std::size_t(prim)] != SampleType::UInt32)
        throw InputError(path + ": the primId channel is not unsigned 32-bit");
    if (!in->readChannels(z, z + 1, SampleType::Float, aov.depth.data()) ||
        !in->readChannels(nx, nx + 3, SampleType::Float, aov.normal.data()) ||
        !in->readChannels(prim, prim + 1, SampleType::UInt32, aov.primId.data()) ||
        !in->readChannels(hit, hit + 1, SampleType::Float, aov.hit.data()))
        throw InputError(path + ": reading failed: " + in->error());
    if (const int albedo = spec.channelIndex("albedo.R"); albedo >= 0) {
        if (spec.channelIndex("albedo.G") != albedo + 1 || spec.channelIndex("albedo.B") != albedo + 2)
            throw InputError(path + ": the albedo.R, albedo.G and albedo.B channels are not consecutive");
        aov.albedo.resize(n);
        if (!in->readChannels(albedo, albedo + 3, SampleType::Float, aov.albedo.data()))
            throw InputError(path + ": reading failed: " + in->error());
    }
    static const std::vector<std::string> fixed = {"Z", "N.X", "N.Y", "N.Z", "primId", "hit", "u", "v",
                                                   "albedo.R", "albedo.G", "albedo.B"};
    for (int c = 0; c < channelCount; ++c) {
        const std::string& name = spec.channelNames[std::size_t(c)];
        if (std::find(fixed.begin(), fixed.end(), name) != fixed.end()) continue;
        AovChannel extra{name, std::vector<float>(n)};
        if (!in->readChannels(c, c + 1, SampleType::Float, extra.values.data()))
            throw InputError(path + ": reading failed: " + in->error());
        aov.extra.push_back(std::move(extra));
    }
    return aov;
}

}  // namespace dacrt
