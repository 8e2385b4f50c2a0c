// libFuzzer target (docs/fuzzing.md): an image embedded in a .glb, decoded by OpenImageIO from
// memory. The bytes are the image; the target places it in the BIN chunk of a quad whose
// material's base colour texture it is (the loader decodes only such images), declared as
// image/png (the loader tells PNG, JPEG and WebP apart by their first bytes, and falls back on
// the declared type), under a 16 MiB memory limit: a header may declare up to that many bytes
// of pixels that are not there, and decoding a few megapixels of nothing under
// AddressSanitizer takes long enough to slow the fuzzer tenfold; a larger image is refused the
// same way. An image that does not decode is a warning, not a refusal; either way,
// anything but a scene or an InputError is a finding, and so is a texture whose pixels are not
// the width x height the loader reports.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_support.hpp"

namespace {

// The quad's JSON, its POSITION (12 floats) and TEXCOORD_0 (8 floats) first in the BIN chunk,
// the image after them.
const std::string kQuad = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":BIN}],
"bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":32},{"buffer":0,"byteOffset":80,"byteLength":IMAGE}],
"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}],
"images":[{"bufferView":2,"mimeType":"image/png"}],"samplers":[{"magFilter":9729}],"textures":[{"source":0,"sampler":0}],
"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"mode":6,"material":0}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]})";

std::string replaced(std::string text, const std::string& key, std::size_t value) {
    text.replace(text.find(key), key.size(), std::to_string(value));
    return text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const float geometry[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1};
    std::vector<unsigned char> bin(reinterpret_cast<const unsigned char*>(geometry),
                                   reinterpret_cast<const unsigned char*>(geometry) + sizeof geometry);
    bin.insert(bin.end(), data, data + size);
    const std::string json = replaced(replaced(kQuad, "BIN", bin.size()), "IMAGE", size);
    const std::optional<dacrt::Scene> scene = dacrt::fuzz::load(dacrt::fuzz::glb(json, bin), "fuzz-image.glb", 16ull << 20);
    if (!scene) return 0;
    for (const dacrt::Texture& t : scene->textures)
        if (!t.rgba.empty() && t.rgba.size() != std::size_t(t.width) * std::size_t(t.height) * 4) {
            std::fprintf(stderr, "image_fuzzer: a %d x %d texture has %zu bytes\n", t.width, t.height, t.rgba.size());
            std::abort();
        }
    return 0;
}
