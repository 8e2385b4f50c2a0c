// Hostile glTF: files built to wrap bounds checks, exhaust the stack or memory, or break the
// specification's rules. Each must end in one InputError naming the file and the problem,
// before anything large is allocated (the sanitizer job runs these under ASan and UBSan;
// tests/cmd/test_cli.cpp runs the same files through `dacrt render`).
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "support/fixtures.hpp"
#include "support/hostile_gltf.hpp"

namespace dacrt {
namespace {

using test::HostileGltf;

class GltfHostile : public ::testing::TestWithParam<HostileGltf> {};

TEST_P(GltfHostile, EndsInOneInputErrorNamingTheFileAndTheProblem) {
    const HostileGltf& h = GetParam();
    const std::string path = test::writeHostileGltf(h);
    try {
        const Scene s = loadGltf(path);
        FAIL() << h.name << " loaded (" << s.triangleCount() << " triangles)";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        EXPECT_NE(message.find(h.expected), std::string::npos) << h.name << ": " << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    }
}

INSTANTIATE_TEST_SUITE_P(Files, GltfHostile, ::testing::ValuesIn(test::hostileGltfFiles()),
                         [](const ::testing::TestParamInfo<HostileGltf>& info) { return info.param.name; });

// A .glb whose BIN chunk declares more bytes than the file holds after it (the glb fuzzer's
// finding: tinygltf copied the declared length, reading past the file's end).
TEST(GltfHostile, AGlbChunkLongerThanTheFileIsRefusedBeforeTheParserReadsIt) {
    auto u32 = [](std::vector<unsigned char>& out, std::uint32_t v) {
        for (int b = 0; b < 4; ++b) out.push_back((unsigned char)(v >> (8 * b)));
    };
    std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36}]})";
    json.resize((json.size() + 3) / 4 * 4, ' ');
    std::vector<unsigned char> chunks;
    u32(chunks, std::uint32_t(json.size()));
    u32(chunks, 0x4E4F534Au);
    chunks.insert(chunks.end(), json.begin(), json.end());
    u32(chunks, 36);
    u32(chunks, 0x004E4942u);
    chunks.resize(chunks.size() + 34, 0);  // two bytes short of what the chunk declares
    std::vector<unsigned char> glb = {'g', 'l', 'T', 'F'};
    u32(glb, 2);
    u32(glb, std::uint32_t(12 + chunks.size()));
    glb.insert(glb.end(), chunks.begin(), chunks.end());
    try {
        loadGltfFromMemory(glb, "short_bin.glb");
        FAIL() << "loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("short_bin.glb: the GLB's chunk 1 (BIN) declares 36 bytes, but 34 follow its header"),
                  std::string::npos)
            << e.what();
    }
}

TEST(GltfHostile, TheSameBytesFromMemoryNeverReadFiles) {
    // A .gltf whose buffer is an external file that exists beside it: read from the file, it
    // loads; from memory, the file is not read.
    const std::string dir = ::testing::TempDir();
    std::ifstream fixture(test::fixture("quad_u8_camera.gltf"));
    nlohmann::json j = nlohmann::json::parse(fixture);
    const std::string uri = j["buffers"][0]["uri"].get<std::string>();
    j["buffers"][0]["uri"] = "hostile_external.bin";
    {
        const std::string base64 = uri.substr(uri.find(',') + 1);
        static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        std::string bytes;
        unsigned bits = 0, count = 0;
        for (char c : base64) {
            const std::size_t v = alphabet.find(c);
            if (v == std::string::npos) continue;
            bits = (bits << 6) | unsigned(v);
            if ((count += 6) >= 8) bytes += char((bits >> (count -= 8)) & 0xFF);
        }
        std::ofstream(dir + "/hostile_external.bin", std::ios::binary) << bytes;
    }
    const std::string path = dir + "/hostile_external.gltf";
    std::ofstream(path) << j.dump();
    EXPECT_EQ(loadGltf(path).triangleCount(), 2u);
    const std::string text = j.dump();
    try {
        loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "memory.gltf");
        FAIL() << "an external file was read from memory input";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("memory.gltf"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace dacrt
