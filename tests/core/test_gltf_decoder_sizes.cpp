// Sizes a decoder's input declares, bounded before anything is allocated for them (issue 29):
// Draco's stream counts held to the accessors and to the file's memory limit, meshopt's
// count x byteStride held to its compressed bytes and to the same limit, and images, each
// under the per-image limit, refused together by it.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "support/data_uri.hpp"

using namespace dacrt;
using dacrt::test::dataUri;

namespace {

// The loader's message for a document it must refuse under `maxBytes`; "(loaded)" when not.
std::string refusal(const nlohmann::json& doc, std::uint64_t maxBytes = 0) {
    const std::string text = doc.dump();
    GltfLimits limits;
    limits.maxBytes = maxBytes;
    try {
        loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "sizes.gltf", limits);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

#define EXPECT_REFUSED(doc, limit, part)                                                        \
    do {                                                                                       \
        const std::string message = refusal(doc, limit);                                      \
        EXPECT_NE(message.find(part), std::string::npos) << message;                           \
        EXPECT_EQ(message.rfind("sizes.gltf: ", 0), 0u) << message;                            \
    } while (0)

// One triangle whose POSITION (and indices, when `indices` is not 0) are view-less accessors of
// the given counts, decoded from a Draco stream of `stream` bytes.
nlohmann::json dracoDocument(const std::vector<unsigned char>& stream, std::uint64_t positions, std::uint64_t indices) {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                          {"extensionsUsed", {"KHR_draco_mesh_compression"}},
                          {"buffers", {{{"byteLength", stream.size()}, {"uri", dataUri(stream)}}}},
                          {"bufferViews", {{{"buffer", 0}, {"byteLength", stream.size()}}}},
                          {"accessors", {{{"componentType", 5126}, {"count", positions}, {"type", "VEC3"}}}},
                          {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}},
                                                        {"extensions", {{"KHR_draco_mesh_compression",
                                                                         {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}}}}}}}}},
                          {"nodes", {{{"mesh", 0}}}},
                          {"scenes", {{{"nodes", {0}}}}}};
    if (indices) {
        doc["accessors"].push_back({{"componentType", 5125}, {"count", indices}, {"type", "SCALAR"}});
        doc["meshes"][0]["primitives"][0]["indices"] = 1;
    }
    return doc;
}

void varint(std::vector<unsigned char>& out, std::uint32_t v) {
    for (; v >= 0x80; v >>= 7) out.push_back(static_cast<unsigned char>(v | 0x80));
    out.push_back(static_cast<unsigned char>(v));
}

// A Draco 2.2 mesh header (method 0: sequential, 1: edgebreaker) followed by `counts` as varints.
std::vector<unsigned char> dracoStream(int method, const std::vector<std::uint32_t>& counts, bool edgebreakerBytes = false) {
    std::vector<unsigned char> s{'D', 'R', 'A', 'C', 'O', 2, 2, 1, static_cast<unsigned char>(method), 0, 0};
    if (method == 1) s.push_back(0);  // the traversal decoder's type
    for (std::size_t i = 0; i < counts.size(); ++i) {
        if (edgebreakerBytes && i == 2) s.push_back(0);  // the attribute data count, a byte
        varint(s, counts[i]);
    }
    s.resize(s.size() + 16, 0);
    return s;
}

}  // namespace

TEST(GltfDecoderSizes, DracoSequentialCountsMustBeTheAccessors) {
    // 1 face and 2^32 - 1 points, for 3 declared positions: refused before Draco sizes its points.
    EXPECT_REFUSED(dracoDocument(dracoStream(0, {1, 0xFFFFFFFFu}), 3, 0), 0,
                   "mesh 0 primitive 0 (KHR_draco_mesh_compression): the stream declares 4294967295 points, the POSITION accessor declares 3");
    // 2^30 faces for the 3 corners declared.
    EXPECT_REFUSED(dracoDocument(dracoStream(0, {1u << 30, 3}), 3, 0), 0,
                   "the stream declares 1073741824 faces (3221225472 corners), the accessors declare 3 vertices");
}

TEST(GltfDecoderSizes, DracoEdgebreakerCountsAreBoundedByItsFaces) {
    // encoded vertices, faces, symbols, split symbols
    EXPECT_REFUSED(dracoDocument(dracoStream(1, {0xFFFFFFF0u, 1, 1, 0}, true), 3, 0), 0,
                   "the edgebreaker stream declares 4294967280 vertices, 1 symbols and 0 split symbols for 1 faces (at most 4 vertices");
    EXPECT_REFUSED(dracoDocument(dracoStream(1, {3, 1, 1000, 0}, true), 3, 0), 0, "1000 symbols");
    EXPECT_REFUSED(dracoDocument(dracoStream(1, {3, 1, 1, 7}, true), 3, 0), 0, "7 split symbols");
    EXPECT_REFUSED(dracoDocument(dracoStream(1, {3, 1u << 28, 1, 0}, true), 3, 0), 0,
                   "the edgebreaker stream declares 268435456 faces (805306368 corners), the accessors declare 3 vertices");
}

TEST(GltfDecoderSizes, DracoHeadersThatAreNoMeshAreRefusedBeforeDecoding) {
    std::vector<unsigned char> pointCloud = dracoStream(0, {1, 3});
    pointCloud[7] = 0;
    EXPECT_REFUSED(dracoDocument(pointCloud, 3, 0), 0, "does not decode (it is not a triangle mesh)");
    std::vector<unsigned char> future = dracoStream(0, {1, 3});
    future[5] = 9;
    EXPECT_REFUSED(dracoDocument(future, 3, 0), 0, "its version 9.2 is unknown");
    std::vector<unsigned char> method = dracoStream(0, {1, 3});
    method[8] = 7;
    EXPECT_REFUSED(dracoDocument(method, 3, 0), 0, "its encoding method 7 is unknown");
    EXPECT_REFUSED(dracoDocument({'D', 'R', 'A', 'C', 'O', 2, 2, 1, 0, 0, 0, 0x80}, 3, 0), 0, "it ends inside its counts");
    EXPECT_REFUSED(dracoDocument({'D', 'R', 'A'}, 3, 0), 0, "its header is not a Draco header");
}

TEST(GltfDecoderSizes, DracoDecodingIsCheckedAgainstTheMemoryLimit) {
    // Counts that agree with view-less accessors of 10 million points: one triangle is planned,
    // but Draco would size 10 million points of its attribute.
    EXPECT_REFUSED(dracoDocument(dracoStream(0, {1, 10000000}), 10000000, 3), 64u << 20,
                   "decoding its 1 attributes has 10000000 elements, which need 640000000 bytes to read, more than the "
                   "67108864-byte limit (over by 572891136)");
}

namespace {

// A buffer view of `count` elements of `stride` bytes compressed by EXT_meshopt_compression into
// `compressed` bytes, used by nothing: every such view is decoded when the file opens.
nlohmann::json meshoptView(std::uint64_t compressed, std::uint64_t count, std::uint64_t stride, const std::string& mode) {
    return {{"buffer", 1}, {"byteLength", count * stride},
            {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteLength", compressed}, {"byteStride", stride},
                                                         {"count", count}, {"mode", mode}}}}}};
}

// The compressed bytes are `header` and zeros: a vertex buffer of version 0 (0xa0) whose every
// delta is zero, valid at its minimum length; nothing else valid.
nlohmann::json meshoptDocument(std::uint64_t compressed, std::vector<nlohmann::json> views, unsigned char header = 0) {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}}, {"extensionsUsed", {"EXT_meshopt_compression"}}};
    std::vector<unsigned char> bytes(compressed, 0);
    if (!bytes.empty()) bytes[0] = header;
    doc["buffers"] = {{{"byteLength", compressed}, {"uri", dataUri(bytes)}},
                      {{"byteLength", std::uint64_t(1) << 40}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
    doc["bufferViews"] = views;
    doc["scenes"] = nlohmann::json::array({nlohmann::json::object()});
    return doc;
}

}  // namespace

TEST(GltfDecoderSizes, MeshoptCountsAreBoundedByTheCompressedBytes) {
    // A vertex block of up to 256 vertices takes 4 header bytes per byte of a 12-byte stride:
    // a million vertices need 187,533 bytes at least (header, 3906 full blocks, one of 64, tail).
    EXPECT_REFUSED(meshoptDocument(40, {meshoptView(40, 1000000, 12, "ATTRIBUTES")}, 0xa0), 0,
                   "buffer view 0 (EXT_meshopt_compression): ATTRIBUTES count 1000000 x byteStride 12 needs at least 187533 "
                   "compressed bytes, byteLength is 40 (short by 187493)");
    // Another version (here 0): two bits per byte of the stride and block at least, 24-byte tail.
    EXPECT_REFUSED(meshoptDocument(40, {meshoptView(40, 1000000, 12, "ATTRIBUTES")}), 0, "needs at least 11746 compressed bytes");
    // At the bound (100,000 vertices: 390 full blocks and one of 160), zero deltas decode.
    EXPECT_REFUSED(meshoptDocument(18788, {meshoptView(18788, 100000, 12, "ATTRIBUTES")}, 0xa0), 0, "(short by 1)");
    EXPECT_REFUSED(meshoptDocument(18789, {meshoptView(18789, 100000, 12, "ATTRIBUTES")}, 0xa0), 0, "no triangles");
    EXPECT_REFUSED(meshoptDocument(40, {meshoptView(40, 3000000, 4, "TRIANGLES")}), 0,
                   "TRIANGLES count 3000000 x byteStride 4 needs at least 1000017 compressed bytes, byteLength is 40 (short by 999977)");
    EXPECT_REFUSED(meshoptDocument(40, {meshoptView(40, 1000, 2, "INDICES")}), 0,
                   "INDICES count 1000 x byteStride 2 needs at least 1005 compressed bytes, byteLength is 40 (short by 965)");
    // A byte short of the bound: refused; at the bound: handed to the decoder, which finds the
    // zeros malformed.
    EXPECT_REFUSED(meshoptDocument(1004, {meshoptView(1004, 1000, 2, "INDICES")}), 0, "(short by 1)");
    EXPECT_REFUSED(meshoptDocument(1005, {meshoptView(1005, 1000, 2, "INDICES")}), 0, "the compressed data is malformed");
}

TEST(GltfDecoderSizes, MeshoptViewsShareTheFileMemoryLimit) {
    // Two views of 100,000 vertices of 12 bytes (1.2 MB each), zero deltas, under a 2 MiB limit:
    // the first is decoded, the second refused with the first counted.
    const nlohmann::json view = meshoptView(18789, 100000, 12, "ATTRIBUTES");
    EXPECT_REFUSED(meshoptDocument(18789, {view}, 0xa0), 1u << 20,
                   "buffer view 0 (EXT_meshopt_compression) has 100000 elements, which need 1200000 bytes to read, more than the "
                   "1048576-byte limit (over by 151424)");
    EXPECT_REFUSED(meshoptDocument(18789, {view, view}, 0xa0), 2u << 20,
                   "buffer view 1 (EXT_meshopt_compression) has 100000 elements, which need 1200000 bytes to read (2400000 with the "
                   "accessors read before it), more than the 2097152-byte limit (over by 302848)");
}

namespace {

std::uint32_t crc32(const unsigned char* p, std::size_t n) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

void put32be(std::vector<unsigned char>& out, std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<unsigned char>(v >> s));
}

void pngChunk(std::vector<unsigned char>& png, const char* type, const std::vector<unsigned char>& data) {
    put32be(png, std::uint32_t(data.size()));
    const std::size_t start = png.size();
    png.insert(png.end(), type, type + 4);
    png.insert(png.end(), data.begin(), data.end());
    put32be(png, crc32(png.data() + start, png.size() - start));
}

// A grey 8-bit PNG of `side` x `side` pixels of value `grey`, its rows in stored (uncompressed)
// deflate blocks.
std::vector<unsigned char> greyPng(std::uint32_t side, unsigned char grey) {
    std::vector<unsigned char> raw;
    for (std::uint32_t y = 0; y < side; ++y) {
        raw.push_back(0);  // filter: none
        raw.insert(raw.end(), side, grey);
    }
    std::vector<unsigned char> z{0x78, 0x01};
    for (std::size_t at = 0; at < raw.size(); at += 65535) {
        const std::size_t n = std::min<std::size_t>(65535, raw.size() - at);
        z.push_back(at + n == raw.size() ? 1 : 0);
        z.insert(z.end(), {static_cast<unsigned char>(n), static_cast<unsigned char>(n >> 8), static_cast<unsigned char>(~n),
                           static_cast<unsigned char>(~n >> 8)});
        z.insert(z.end(), raw.begin() + std::ptrdiff_t(at), raw.begin() + std::ptrdiff_t(at + n));
    }
    std::uint32_t a = 1, b = 0;
    for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
    put32be(z, b << 16 | a);
    std::vector<unsigned char> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    std::vector<unsigned char> header;
    put32be(header, side);
    put32be(header, side);
    header.insert(header.end(), {8, 0, 0, 0, 0});
    pngChunk(png, "IHDR", header);
    pngChunk(png, "IDAT", z);
    pngChunk(png, "IEND", {});
    return png;
}

}  // namespace

TEST(GltfDecoderSizes, ImagesUnderTheImageLimitAreRefusedTogetherByTheFileLimit) {
    // Eight 64 x 64 images, 16 KiB each decoded (far under the 1 GiB per image), each the base
    // colour of a material of its own; under a 100 KiB limit six fit, the last two are refused
    // (a warning each, their materials shaded with their factor) and the quad still loads.
    const float quad[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, 0, 0, 1, 0, 1, 1, 1};
    const unsigned char* q = reinterpret_cast<const unsigned char*>(quad);
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                          {"buffers", {{{"byteLength", sizeof quad}, {"uri", dataUri(std::vector<unsigned char>(q, q + sizeof quad))}}}},
                          {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}, {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 28}}}},
                          {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                                         {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}}}},
                          {"nodes", {{{"mesh", 0}}}},
                          {"scenes", {{{"nodes", {0}}}}}};
    for (int i = 0; i < 8; ++i) {
        const std::vector<unsigned char> png = greyPng(64, static_cast<unsigned char>(30 * i));
        doc["images"].push_back({{"uri", "data:image/png;base64," + dacrt::test::base64(png)}});
        doc["textures"].push_back({{"source", i}});
        doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}}}});
        doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", i}});
    }
    const std::string text = doc.dump();
    GltfLimits limits;
    limits.maxBytes = 100 << 10;
    const Scene s = loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "images.gltf", limits);
    int refused = 0;
    for (const std::string& w : s.warnings)
        if (w.find("more than the 102400-byte memory limit") != std::string::npos) ++refused;
    EXPECT_EQ(refused, 2) << ::testing::PrintToString(s.warnings);
    std::size_t decoded = 0;
    for (const auto& t : s.textures) decoded += !t.rgba.empty();
    EXPECT_EQ(decoded, 6u);
    // With room for all eight, none is refused.
    limits.maxBytes = 200 << 10;
    const Scene all = loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "images.gltf", limits);
    EXPECT_TRUE(all.warnings.empty()) << ::testing::PrintToString(all.warnings);
}
