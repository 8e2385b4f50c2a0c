#include "core/gltf_materials.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string_view>

#include "core/data_uri.hpp"
#include "core/errors.hpp"
#include "core/image_codecs.hpp"
#include "core/input_file.hpp"

namespace dacrt::gltf {
namespace {

// Decoded images larger than this are refused with a warning (a 16k x 16k RGBA8 texture).
constexpr std::uint64_t kMaxTextureBytes = std::uint64_t(1) << 30;

// The formats dacrt decodes, told apart by their first bytes (a mimeType may contradict them):
// each is read by its own OpenImageIO reader alone. Given a file name, OpenImageIO would try
// every reader it has on bytes its named one refuses (GIF, TIFF, OpenEXR, FITS, ...), readers
// that this input need not reach (a GIF of 65535 x 65535 made one of them throw).
struct ImageFormat {
    std::string_view magic;
    std::size_t at;       // where the magic lies
    const char* reader;   // OpenImageIO's format name; null: a format dacrt does not decode
    const char* name;
};
using namespace std::string_view_literals;
constexpr ImageFormat kImageFormats[] = {
    {"\x89PNG"sv, 0, "png", "PNG"},
    {"\xFF\xD8\xFF"sv, 0, "jpeg", "JPEG"},
    {"WEBP"sv, 8, "webp", "WebP"},  // after "RIFF" and the size
    {"GIF8"sv, 0, nullptr, "GIF"},
    {"BM"sv, 0, nullptr, "BMP"},
    {"II*\0"sv, 0, nullptr, "TIFF"},
    {"MM\0*"sv, 0, nullptr, "TIFF"},
    {"\xABKTX 20"sv, 0, nullptr, "KTX2 (KHR_texture_basisu)"},
    {"DDS "sv, 0, nullptr, "DDS (MSFT_texture_dds)"},
    {"v/1\x01"sv, 0, nullptr, "OpenEXR"},
    {"#?RADIANCE"sv, 0, nullptr, "Radiance HDR"},
};

const ImageFormat* formatOf(std::span<const unsigned char> b) {
    for (const ImageFormat& f : kImageFormats) {
        const std::size_t n = f.magic.size();
        if (b.size() >= f.at + n && std::memcmp(b.data() + f.at, f.magic.data(), n) == 0 &&
            (f.at == 0 || std::memcmp(b.data(), "RIFF", 4) == 0))
            return &f;
    }
    return nullptr;
}

// Why bytes are not decoded: what they are, where their first bytes say.
std::string unsupportedFormat(const ImageFormat* f, const std::string& mimeType) {
    const std::string declared = mimeType.empty() ? std::string() : ", declared " + mimeType;
    if (f) return "it is " + std::string(f->name) + declared + "; dacrt decodes PNG, JPEG and WebP";
    return "its bytes are neither PNG, JPEG nor WebP" + declared;
}

std::string percentDecoded(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit((unsigned char)uri[i + 1]) && std::isxdigit((unsigned char)uri[i + 2])) {
            out.push_back(char(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
            i += 2;
        } else {
            out.push_back(uri[i]);
        }
    }
    return out;
}

// Decodes to 8-bit RGBA (grey expands to RGB, alpha 255 where absent); empty with `why` set
// when it cannot. Its RGBA bytes are counted against the reader's limit (with every accessor
// and image decoded before it) before its pixels are read: many images, each under the
// per-image limit, are as many allocations.
Texture decodeWith(const ImageFormat& format, std::span<const unsigned char> bytes, const AccessorReader& budget,
                   std::string& why) {
    Texture t;
    std::string openError;
    const std::unique_ptr<ImageReader> in = imageCodecs().openMemory(format.reader, bytes, openError);
    if (!in) {
        why = "it does not decode (" + openError + ")";
        return t;
    }
    const ImageHeader& spec = in->header();
    const int channels = int(spec.channelNames.size());
    const std::uint64_t texels = std::uint64_t(std::max(spec.width, 0)) * std::uint64_t(std::max(spec.height, 0));
    if (spec.width <= 0 || spec.height <= 0 || channels <= 0 || texels * 4 > kMaxTextureBytes) {
        why = "its size " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " is empty or over the " +
              std::to_string(kMaxTextureBytes >> 20) + " MiB texture limit";
        return t;
    }
    if (!budget.tryReserve(texels * 4)) {
        why = "its " + std::to_string(texels * 4) + " bytes decoded, with the file's data decoded before it, are more than the " +
              std::to_string(budget.byteLimit()) + "-byte memory limit";
        return t;
    }
    std::vector<std::uint8_t> raw(std::size_t(texels) * std::size_t(channels));
    if (!in->readChannels(0, channels, SampleType::UInt8, raw.data())) {
        why = "its pixels do not decode (" + in->error() + ")";
        return t;
    }
    t.width = spec.width;
    t.height = spec.height;
    t.rgba.resize(std::size_t(texels) * 4);
    for (std::size_t i = 0; i < texels; ++i) {
        const std::uint8_t* p = raw.data() + i * std::size_t(channels);
        std::uint8_t* q = t.rgba.data() + i * 4;
        const bool grey = channels <= 2;
        q[0] = p[0];
        q[1] = grey ? p[0] : p[1];
        q[2] = grey ? p[0] : p[2];
        q[3] = channels == 2 ? p[1] : channels >= 4 ? p[3] : 255;
    }
    return t;
}

// The image's format from its first bytes, then its own reader; empty, with `why` set, where
// it is not decoded.
Texture decodeImage(std::span<const unsigned char> bytes, const std::string& mimeType, const AccessorReader& budget,
                    std::string& why) {
    const ImageFormat* format = formatOf(bytes);
    if (!format || !format->reader) {
        why = unsupportedFormat(format, mimeType);
        return {};
    }
    imageCodecs();  // a missing module is the installation's fault: an error, not the image's warning
    try {
        return decodeWith(*format, bytes, budget, why);
    } catch (const std::exception& e) {  // a reader's own failure (an allocation, a bad length)
        why = "its " + std::string(format->name) + " reader failed (" + e.what() + ")";
        return {};
    }
}

TextureWrap wrapOf(int mode) {
    if (mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return TextureWrap::ClampToEdge;
    if (mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return TextureWrap::MirroredRepeat;
    return TextureWrap::Repeat;
}

// An index held as a JSON number: fallback when absent, -1 unless an integer in [0, 2^31).
int indexOf(const tinygltf::Value& object, const char* key, int fallback) {
    const std::int64_t i = integerMember(object, key, fallback);
    return i < 2147483648ll ? int(i) : -1;
}

// A textureInfo object held in an extension's JSON (tinygltf parses only the core ones).
tinygltf::TextureInfo textureInfoOf(const tinygltf::Value& v) {
    tinygltf::TextureInfo info;
    info.index = indexOf(v, "index", -1);
    info.texCoord = std::max(indexOf(v, "texCoord", 0), 0);
    if (v.Has("extensions") && v.Get("extensions").IsObject() && v.Get("extensions").Has("KHR_texture_transform"))
        info.extensions["KHR_texture_transform"] = v.Get("extensions").Get("KHR_texture_transform");
    return info;
}

class MaterialReader {
public:
    MaterialReader(const AccessorReader& reader, const ImageSource& source, Scene& scene)
        : reader_(reader), model_(reader.model()), source_(source), scene_(scene) {}

    void run() {
        for (std::size_t m = 0; m < model_.materials.size(); ++m) scene_.materials.push_back(material(m));
    }

private:
    Material material(std::size_t index) {
        const tinygltf::Material& m = model_.materials[index];
        Material mat;
        mat.name = m.name;
        const std::vector<double>& f = m.pbrMetallicRoughness.baseColorFactor;
        if (f.size() == 4) mat.baseColor = glm::vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
        mat.doubleSided = m.doubleSided;
        tinygltf::TextureInfo info = m.pbrMetallicRoughness.baseColorTexture;
        // The archived specular-glossiness workflow (required by older files, Khronos' samples
        // among them): its diffuse colour is what the preview shows as the base colour.
        if (auto sg = m.extensions.find("KHR_materials_pbrSpecularGlossiness"); sg != m.extensions.end() && sg->second.IsObject()) {
            const tinygltf::Value& x = sg->second;
            mat.baseColor = glm::vec4(float(numberMember(x, "diffuseFactor", 0, 1.0)), float(numberMember(x, "diffuseFactor", 1, 1.0)),
                                      float(numberMember(x, "diffuseFactor", 2, 1.0)), float(numberMember(x, "diffuseFactor", 3, 1.0)));
            info = tinygltf::TextureInfo{};
            if (x.Has("diffuseTexture") && x.Get("diffuseTexture").IsObject()) info = textureInfoOf(x.Get("diffuseTexture"));
        }
        for (int k = 0; k < 4; ++k)
            if (!std::isfinite(mat.baseColor[k])) reader_.fail("material " + std::to_string(index) + ": the base colour is not finite");
        if (info.index >= 0) mat.baseColorTexture = binding(info, "material " + std::to_string(index) + " '" + m.name + "'");
        return mat;
    }

    TextureBinding binding(const tinygltf::TextureInfo& info, const std::string& where) {
        TextureBinding b;
        if (std::size_t(info.index) >= model_.textures.size())
            reader_.fail(where + ": baseColorTexture names texture " + std::to_string(info.index) + ", which does not exist");
        const tinygltf::Texture& tex = model_.textures[std::size_t(info.index)];
        b.texCoord = std::uint32_t(std::max(info.texCoord, 0));
        if (auto t = info.extensions.find("KHR_texture_transform"); t != info.extensions.end() && t->second.IsObject()) {
            const tinygltf::Value& x = t->second;
            const double ox = numberMember(x, "offset", 0, 0.0), oy = numberMember(x, "offset", 1, 0.0);
            const double sx = numberMember(x, "scale", 0, 1.0), sy = numberMember(x, "scale", 1, 1.0), r = numberMember(x, "rotation", 0, 0.0);
            if (!std::isfinite(ox + oy + sx + sy + r)) reader_.fail(where + ": KHR_texture_transform has a non-finite number");
            const double c = std::cos(r), s = std::sin(r);
            // uv' = T R S uv (the extension's order), as columns.
            b.transform = glm::mat3(glm::dmat3(sx * c, -sx * s, 0.0, sy * s, sy * c, 0.0, ox, oy, 1.0));
            const double texCoord = numberMember(x, "texCoord", 0, -1.0);
            if (texCoord >= 0.0 && texCoord < 256.0) b.texCoord = std::uint32_t(texCoord);
        }
        if (tex.sampler >= 0) {
            if (std::size_t(tex.sampler) >= model_.samplers.size())
                reader_.fail(where + ": texture " + std::to_string(info.index) + " names sampler " + std::to_string(tex.sampler) + ", which does not exist");
            const tinygltf::Sampler& s = model_.samplers[std::size_t(tex.sampler)];
            b.wrapS = wrapOf(s.wrapS);
            b.wrapT = wrapOf(s.wrapT);
            b.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
        }
        int image = tex.source;
        for (const char* alternative : {"EXT_texture_webp", "KHR_texture_basisu", "MSFT_texture_dds"})
            if (auto e = tex.extensions.find(alternative); image < 0 && e != tex.extensions.end() && e->second.IsObject())
                image = indexOf(e->second, "source", -1);
        if (image < 0) {
            warn(reader_.name() + ": " + where + ": its base colour texture has no image dacrt can read; shaded with the base colour factor");
            return b;
        }
        if (std::size_t(image) >= model_.images.size())
            reader_.fail(where + ": texture " + std::to_string(info.index) + " names image " + std::to_string(image) + ", which does not exist");
        b.texture = decoded(image, where);
        return b;
    }

    int decoded(int image, const std::string& where) {
        if (auto it = decodedImage_.find(image); it != decodedImage_.end()) return it->second;
        const tinygltf::Image& img = model_.images[std::size_t(image)];
        const std::string label = "image " + std::to_string(image) + (img.name.empty() ? "" : " '" + img.name + "'") +
                                  (img.uri.empty() || img.uri.rfind("data:", 0) == 0 ? "" : " (" + img.uri + ")");
        std::string why;
        std::vector<unsigned char> fileBytes;
        std::span<const unsigned char> bytes;
        if (img.bufferView >= 0) {
            bytes = reader_.viewBytes(img.bufferView, label);
        } else if (!img.image.empty()) {
            bytes = img.image;
        } else if (img.uri.starts_with("data:")) {
            fileBytes = dataUriBytes(img.uri, why);
            bytes = fileBytes;
        } else if (!img.uri.empty() && source_.readFiles) {
            const std::filesystem::path path = std::filesystem::path(source_.baseDir) / percentDecoded(img.uri);
            try {
                fileBytes = readRegularInput(path.string(), kMaxTextureBytes);
                bytes = fileBytes;
            } catch (const InputError& e) {
                why = e.what();
            }
        } else {
            why = img.uri.empty() ? "it has no data" : "files named by uri are not read from memory input";
        }
        int result = -1;
        if (why.empty()) {
            Texture t = decodeImage(bytes, img.mimeType, reader_, why);
            if (why.empty()) {
                t.name = img.name.empty() ? "image " + std::to_string(image) : img.name;
                result = int(scene_.textures.size());
                scene_.textures.push_back(std::move(t));
            }
        }
        if (result < 0) warn(reader_.name() + ": " + label + " (" + where + "): " + why + "; shaded with the base colour factor");
        decodedImage_[image] = result;
        return result;
    }

    void warn(const std::string& line) { scene_.warnings.push_back(line); }

    const AccessorReader& reader_;
    const tinygltf::Model& model_;
    const ImageSource& source_;
    Scene& scene_;
    std::map<int, int> decodedImage_;
};

}  // namespace

bool keepEncodedImage(tinygltf::Image* image, int, std::string*, std::string*, int, int, const unsigned char* bytes,
                      int size, void*) {
    if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
    return true;
}

void readMaterials(const AccessorReader& reader, const ImageSource& source, Scene& scene) {
    MaterialReader(reader, source, scene).run();
}

}  // namespace dacrt::gltf
