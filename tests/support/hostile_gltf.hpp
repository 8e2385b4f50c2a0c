#pragma once
// Hostile glTF files, each built from the valid tests/scenes/quad_u8_camera.gltf by one
// change, with the part of the message that must name its problem. Used by the loader's
// tests and, through `dacrt render`, by the command-line tests.
#include <fstream>
#include <unistd.h>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/fixtures.hpp"

namespace dacrt::test {

struct HostileGltf {
    std::string name;
    std::string expected;                    // part of the error message
    std::function<std::string()> contents;   // the file's text
};

inline void PrintTo(const HostileGltf& h, std::ostream* os) { *os << h.name; }

inline nlohmann::json quadGltf() {
    std::ifstream f(fixture("quad_u8_camera.gltf"));
    return nlohmann::json::parse(f);
}

// The quad with one change made to its JSON.
inline std::function<std::string()> changed(std::function<void(nlohmann::json&)> change) {
    return [change] {
        nlohmann::json j = quadGltf();
        change(j);
        return j.dump();
    };
}

inline std::vector<HostileGltf> hostileGltfFiles() {
    static constexpr std::uint64_t kNear2To64 = 18446744073709551600ull;  // a multiple of 4
    static constexpr std::uint64_t k2To62 = 4611686018427387904ull;
    std::vector<HostileGltf> files = {
        {"BufferViewOffsetNear2To64", "overflows 64 bits",
         changed([](nlohmann::json& j) { j["bufferViews"][0]["byteOffset"] = kNear2To64; })},
        {"AccessorOffsetNear2To64", "overflows 64 bits",
         changed([](nlohmann::json& j) { j["accessors"][0]["byteOffset"] = kNear2To64; })},
        {"PositionCountWraps", "overflows 64 bits", changed([](nlohmann::json& j) { j["accessors"][0]["count"] = k2To62 + 1; })},
        {"IndexCountPastTheBuffer", "runs past the end of buffer view 1",
         changed([](nlohmann::json& j) { j["accessors"][1]["count"] = std::uint64_t(1) << 40; })},
        {"CameraZnearZero", "znear", changed([](nlohmann::json& j) { j["cameras"][0]["perspective"]["znear"] = 0.0; })},
        {"CameraZnearNegative", "znear", changed([](nlohmann::json& j) { j["cameras"][0]["perspective"]["znear"] = -1.0; })},
        {"CameraZfarBeforeZnear", "zfar",
         changed([](nlohmann::json& j) {
             j["cameras"][0]["perspective"]["znear"] = 2.0;
             j["cameras"][0]["perspective"]["zfar"] = 1.0;
         })},
        {"NodeNamesAMissingCamera", "nodes[1].camera 7 is out of range (1 camera)",
         changed([](nlohmann::json& j) { j["nodes"][1]["camera"] = 7; })},
        {"ByteStrideBelowTheElement", "smaller than the 12-byte elements",
         changed([](nlohmann::json& j) { j["bufferViews"][0]["byteStride"] = 4; })},
        {"UnalignedAccessorOffset", "not aligned", changed([](nlohmann::json& j) { j["accessors"][0]["byteOffset"] = 2; })},
        {"RotationNotUnit", "rotation quaternion has length",
         changed([](nlohmann::json& j) { j["nodes"][0]["rotation"] = {0, 0, 0, 2}; })},
        {"RequiredExtension", "requires the extension EXT_unheard_of_geometry, which dacrt does not support",
         changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"EXT_unheard_of_geometry"};
             j["extensionsRequired"] = {"EXT_unheard_of_geometry"};
         })},
        // The forms and extensions the loader decodes, each broken once.
        {"SparseIndexOutOfRange", "index 128 is out of range for 4 elements", changed([](nlohmann::json& j) {
             // Byte 2 of the positions (-1.0f: 00 00 80 bf) read as an index: 128.
             j["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", 0}, {"componentType", 5121}, {"byteOffset", 2}}},
                                            {"values", {{"bufferView", 0}}}};
         })},
        {"SparseIndicesPastTheirView", "run past the end of buffer view 1", changed([](nlohmann::json& j) {
             j["accessors"][0]["sparse"] = {{"count", 4}, {"indices", {{"bufferView", 1}, {"componentType", 5125}}},
                                            {"values", {{"bufferView", 0}}}};
         })},
        {"SparseCountAboveTheAccessor", "not in 1..4", changed([](nlohmann::json& j) {
             j["accessors"][0]["sparse"] = {{"count", 5}, {"indices", {{"bufferView", 1}, {"componentType", 5121}}},
                                            {"values", {{"bufferView", 0}}}};
         })},
        {"QuantizedWithoutTheExtension", "needs the extension KHR_mesh_quantization", changed([](nlohmann::json& j) {
             j["accessors"][0]["componentType"] = 5122;
         })},
        {"MeshoptCountDisagreesWithTheView", "count x byteStride is 12 bytes", changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"EXT_meshopt_compression"};
             j["bufferViews"][0]["extensions"] = {{"EXT_meshopt_compression",
                                                   {{"buffer", 0}, {"byteLength", 48}, {"byteStride", 12}, {"count", 1}, {"mode", "ATTRIBUTES"}}}};
         })},
        {"MeshoptSourcePastTheBuffer", "run past the end of buffer 0", changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"EXT_meshopt_compression"};
             j["bufferViews"][0]["extensions"] = {{"EXT_meshopt_compression",
                                                   {{"buffer", 0}, {"byteOffset", 40}, {"byteLength", 4096}, {"byteStride", 12}, {"count", 4},
                                                    {"mode", "ATTRIBUTES"}}}};
         })},
        {"MeshoptMalformedStream", "malformed (meshoptimizer error", changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"EXT_meshopt_compression"};
             j["bufferViews"][0]["extensions"] = {{"EXT_meshopt_compression",
                                                   {{"buffer", 0}, {"byteLength", 48}, {"byteStride", 12}, {"count", 4}, {"mode", "ATTRIBUTES"}}}};
         })},
        {"DracoViewMissing", "KHR_draco_mesh_compression.bufferView 9 is out of range (2 bufferViews)", changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
             j["meshes"][0]["primitives"][0]["extensions"] = {
                 {"KHR_draco_mesh_compression", {{"bufferView", 9}, {"attributes", {{"POSITION", 0}}}}}};
         })},
        {"DracoStreamIsNotDraco", "does not decode", changed([](nlohmann::json& j) {
             j["extensionsUsed"] = {"KHR_draco_mesh_compression"};
             j["meshes"][0]["primitives"][0]["extensions"] = {
                 {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
         })},
        {"TextureNamesAMissingImage", "textures[0].source 4 is out of range (0 images)", changed([](nlohmann::json& j) {
             j["textures"] = {{{"source", 4}}};
             j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
         })},
        {"ImageViewPastTheBuffer", "runs past the end of buffer 0", changed([](nlohmann::json& j) {
             j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 40}, {"byteLength", 1000000}});
             j["images"] = {{{"bufferView", 2}, {"mimeType", "image/png"}}};
             j["textures"] = {{{"source", 0}}};
             j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
         })},
        {"LightThatDoesNotExist", "nodes[1].extensions.KHR_lights_punctual.light 3 is out of range (0 lights)", changed([](nlohmann::json& j) {
             j["nodes"][1]["extensions"] = {{"KHR_lights_punctual", {{"light", 3}}}};
         })},
        // The specification's index, integer and type rules, checked on the JSON (tinygltf casts
        // an index to int, so 2^32 read as 0, and skips a member of the wrong type).
        {"MaterialTextureOutOfRange", "materials[0].pbrMetallicRoughness.baseColorTexture.index 7 is out of range (1 texture)",
         changed([](nlohmann::json& j) {
             j["textures"] = {{{"source", 0}}};
             j["images"] = {{{"uri", "missing.png"}}};
             j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 7}};
         })},
        {"NormalTextureOutOfRange", "materials[0].normalTexture.index 2 is out of range (0 textures)",
         changed([](nlohmann::json& j) { j["materials"][0]["normalTexture"] = {{"index", 2}}; })},
        {"TextureSamplerOutOfRange", "textures[0].sampler 1 is out of range (0 samplers)",
         changed([](nlohmann::json& j) { j["textures"] = {{{"sampler", 1}}}; })},
        {"LightIndexFractional", "nodes[1].extensions.KHR_lights_punctual.light 0.5 is not an integer",
         changed([](nlohmann::json& j) {
             j["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}}}}}}};
             j["nodes"][1]["extensions"] = {{"KHR_lights_punctual", {{"light", 0.5}}}};
         })},
        {"MeshIndex2To32", "nodes[0].mesh 4294967296 is out of range (1 mesh)",
         changed([](nlohmann::json& j) { j["nodes"][0]["mesh"] = std::uint64_t(1) << 32; })},
        {"MeshIndexFractional", "nodes[0].mesh 0.5 is not an integer", changed([](nlohmann::json& j) { j["nodes"][0]["mesh"] = 0.5; })},
        {"ByteOffsetNegative", "bufferViews[1].byteOffset -48 is negative",
         changed([](nlohmann::json& j) { j["bufferViews"][1]["byteOffset"] = -48; })},
        {"ComponentTypeWraps", "accessors[1].componentType 4294972417 is larger than 2147483647",
         changed([](nlohmann::json& j) { j["accessors"][1]["componentType"] = (std::uint64_t(1) << 32) + 5121; })},
        {"ExtensionsRequiredNotAnArray", "extensionsRequired is not an array",
         changed([](nlohmann::json& j) { j["extensionsRequired"] = "EXT_unheard_of_geometry"; })},
        {"ExtensionsUsedHoldsANumber", "extensionsUsed[0] 7 is not a string",
         changed([](nlohmann::json& j) { j["extensionsUsed"] = {7}; })},
        {"EmptyScenesWithADefault", "scene 0 is out of range (0 scenes)", changed([](nlohmann::json& j) {
             j["scenes"] = nlohmann::json::array();
             j["scene"] = 0;
         })},
        {"AnimationTargetsAMissingNode", "animations[0].channels[0].target.node 9 is out of range (2 nodes)",
         changed([](nlohmann::json& j) {
             j["animations"] = {{{"channels", {{{"sampler", 0}, {"target", {{"node", 9}, {"path", "translation"}}}}}},
                                 {"samplers", {{{"input", 0}, {"output", 0}}}}}};
         })},
        {"AnimationChannelNamesAMissingSampler", "animations[0].channels[0].sampler 1 is out of range (1 sampler)",
         changed([](nlohmann::json& j) {
             j["animations"] = {{{"channels", {{{"sampler", 1}, {"target", {{"node", 0}, {"path", "translation"}}}}}},
                                 {"samplers", {{{"input", 0}, {"output", 0}}}}}};
         })},
        {"GlbVersion1", "the GLB header's version is 1, not 2", [] {
             const std::string json = quadGltf().dump() + std::string((4 - quadGltf().dump().size() % 4) % 4, ' ');
             auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
             return "glTF" + u32(1) + u32(std::uint32_t(20 + json.size())) + u32(std::uint32_t(json.size())) + "JSON" + json;
         }},
        {"SceneListsANodeTwice", "twice", changed([](nlohmann::json& j) { j["scenes"][0]["nodes"] = {0, 0, 1}; })},
        {"RootIsAChild", "is a root of scene 0 but a child",
         changed([](nlohmann::json& j) { j["nodes"][1]["children"] = {0}; })},
    };
    // A node chain 100,000 deep, the mesh at its end.
    files.push_back({"NodeChain100000Deep", "deeper than 1024 levels", changed([](nlohmann::json& j) {
                         const nlohmann::json camera = j["nodes"][1];
                         nlohmann::json nodes = nlohmann::json::array();
                         for (int i = 0; i < 100000; ++i) nodes.push_back({{"children", {i + 1}}});
                         nodes.push_back({{"mesh", 0}});
                         nodes.push_back(camera);
                         j["nodes"] = nodes;
                         j["scenes"][0]["nodes"] = {0, 100001};
                     })});
    // Every node of a level listed as a child of both nodes of the level above: 2^20 instances
    // from a file of a few kilobytes.
    files.push_back({"NodesUnderTwoParents", "is a child of both", changed([](nlohmann::json& j) {
                         nlohmann::json nodes = nlohmann::json::array();
                         for (int level = 0; level < 20; ++level)
                             for (int k = 0; k < 2; ++k) nodes.push_back({{"children", {2 * level + 2, 2 * level + 3}}});
                         nodes.push_back({{"mesh", 0}});
                         nodes.push_back({{"mesh", 0}});
                         j["nodes"] = nodes;
                         j["scenes"][0]["nodes"] = {0, 1};
                     })});
    // extras nested 100,000 deep: text, since a JSON library would recurse to build it.
    files.push_back({"ExtrasNested100000Deep", "more than 256 levels deep", [] {
                         std::string text = quadGltf().dump();
                         const std::string deep = std::string(100000, '[') + std::string(100000, ']');
                         return "{\"extras\":" + deep + "," + text.substr(1);
                     }});
    // 100,000 zero-area triangles (all corners the same vertex) and nothing else.
    files.push_back({"OnlyZeroAreaTriangles", "all 100000 have no area", changed([](nlohmann::json& j) {
                         j["accessors"][1]["count"] = 300000;
                         j["bufferViews"][1]["byteLength"] = 300000;
                         j["buffers"][0]["byteLength"] = 48 + 300000;
                         j["buffers"][0]["uri"] =
                             std::string(j["buffers"][0]["uri"]).substr(0, 37 + 64) +  // the positions, whole
                             std::string(400000, 'A');                                 // zero indices
                     })});
    return files;
}

// Writes the file to the test's temporary folder and returns its path; the process id keeps
// the loader's and the CLI's tests, which write the same files, apart under `ctest -j`.
inline std::string writeHostileGltf(const HostileGltf& h) {
    const std::string path =
        ::testing::TempDir() + "/dacrt_hostile_" + h.name + "_" + std::to_string(getpid()) + ".gltf";
    std::ofstream(path) << h.contents();
    return path;
}

}  // namespace dacrt::test
