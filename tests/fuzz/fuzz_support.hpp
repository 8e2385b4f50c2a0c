#pragma once
// What the fuzz targets (docs/fuzzing.md) share: the loader's limits under libFuzzer, a .glb
// made of a JSON text and a binary chunk, and a load whose refusal (InputError) is the
// expected end of bad input. Anything else leaving the loader is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"

namespace dacrt::fuzz {

// The loader's own memory limit, far below libFuzzer's -malloc_limit_mb (run_fuzz.sh passes
// 2048): a file that asks for more must be refused by the loader, not by the allocator.
constexpr std::uint64_t kMaxBytes = 256ull << 20;

// DACRT_FUZZ_VERBOSE=1: one line per load saying what became of it (for replaying a corpus).
inline bool verbose() {
    static const bool v = std::getenv("DACRT_FUZZ_VERBOSE") != nullptr;
    return v;
}

inline void put32(std::vector<unsigned char>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

// The chunks of a .glb (JSON padded with spaces, BIN with zeros, as the format asks), without
// the 12-byte header.
inline std::vector<unsigned char> glbChunks(std::span<const unsigned char> json, std::span<const unsigned char> bin) {
    std::vector<unsigned char> out;
    const auto chunk = [&](std::span<const unsigned char> data, const char* type, unsigned char pad) {
        const std::size_t padded = (data.size() + 3) / 4 * 4;
        put32(out, std::uint32_t(padded));
        out.insert(out.end(), type, type + 4);
        out.insert(out.end(), data.begin(), data.end());
        out.resize(out.size() + padded - data.size(), pad);
    };
    chunk(json, "JSON", ' ');
    if (!bin.empty()) chunk(bin, "BIN\0", 0);
    return out;
}

// A .glb: the header (magic, version 2, total length) before `chunks`.
inline std::vector<unsigned char> glbWithHeader(std::span<const unsigned char> chunks) {
    std::vector<unsigned char> glb{'g', 'l', 'T', 'F'};
    put32(glb, 2);
    put32(glb, std::uint32_t(12 + chunks.size()));
    glb.insert(glb.end(), chunks.begin(), chunks.end());
    return glb;
}

inline std::vector<unsigned char> glb(const std::string& json, std::span<const unsigned char> bin) {
    return glbWithHeader(glbChunks({reinterpret_cast<const unsigned char*>(json.data()), json.size()}, bin));
}

// A document of one primitive, in one mesh placed by one node of one scene, that uses the
// extension `extension` (required when `required`).
inline nlohmann::json onePrimitiveDocument(const char* extension, bool required, nlohmann::json buffers, nlohmann::json views,
                                           nlohmann::json accessors, nlohmann::json primitive) {
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}},
                          {"extensionsUsed", {extension}},
                          {"buffers", std::move(buffers)},
                          {"bufferViews", std::move(views)},
                          {"accessors", std::move(accessors)},
                          {"meshes", {{{"primitives", {std::move(primitive)}}}}},
                          {"nodes", {{{"mesh", 0}}}},
                          {"scenes", {{{"nodes", {0}}}}}};
    if (required) doc["extensionsRequired"] = {extension};
    return doc;
}

// The scene the bytes load to under a memory limit of `maxBytes`, or nothing when the loader
// refuses them.
inline std::optional<Scene> load(std::span<const unsigned char> bytes, const char* name, std::uint64_t maxBytes = kMaxBytes) {
    GltfLimits limits;
    limits.maxBytes = maxBytes;
    try {
        Scene scene = loadGltfFromMemory(bytes, name, limits);
        if (verbose())
            std::fprintf(stderr, "%s: loaded %zu triangles, %zu textures, %zu warnings\n", name, scene.triangles.size(),
                         scene.textures.size(), scene.warnings.size());
        return scene;
    } catch (const InputError& e) {
        if (verbose()) std::fprintf(stderr, "%s: refused: %s\n", name, e.what());
        return std::nullopt;
    }
}

}  // namespace dacrt::fuzz
