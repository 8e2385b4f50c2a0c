#include "core/gltf_container.hpp"

#include <cstdint>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/mapped_memory.hpp"

namespace dacrt::gltf {
namespace {

using nlohmann::json;

// Four zero bytes: what a stand-in view and buffer hold. The reader never reads them.
constexpr const char* kStandInUri = "data:application/octet-stream;base64,AAAAAA==";

struct GlbParts {
    std::string_view json;
    std::span<const unsigned char> rest;  // the chunks after the JSON chunk, as they are
    bool hasBinChunk = false;
};

std::uint32_t readU32(std::span<const unsigned char> bytes, std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
}

bool splitGlb(std::span<const unsigned char> bytes, GlbParts& parts) {
    if (bytes.size() < 20 || std::memcmp(bytes.data(), "glTF", 4) != 0) return false;
    if (readU32(bytes, 8) != bytes.size()) return false;
    const std::uint64_t jsonLength = readU32(bytes, 12);
    if (readU32(bytes, 16) != 0x4E4F534Au || 20 + jsonLength > bytes.size()) return false;
    parts.json = {reinterpret_cast<const char*>(bytes.data()) + 20, std::size_t(jsonLength)};
    parts.rest = bytes.subspan(std::size_t(20 + jsonLength));
    parts.hasBinChunk = parts.rest.size() >= 8 && readU32(parts.rest, 4) == 0x004E4942u;
    return true;
}

void appendU32(std::vector<unsigned char>& out, std::uint32_t v) {
    unsigned char b[4];
    std::memcpy(b, &v, 4);
    out.insert(out.end(), b, b + 4);
}

std::vector<unsigned char> joinGlb(const std::string& jsonText, std::span<const unsigned char> rest) {
    std::string padded = jsonText;
    while (padded.size() % 4) padded.push_back(' ');
    std::vector<unsigned char> out;
    reserveMapped(out, 20 + padded.size() + rest.size());
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    appendU32(out, 2);
    appendU32(out, std::uint32_t(20 + padded.size() + rest.size()));
    appendU32(out, std::uint32_t(padded.size()));
    appendU32(out, 0x4E4F534Au);
    out.insert(out.end(), padded.begin(), padded.end());
    out.insert(out.end(), rest.begin(), rest.end());
    return out;
}

bool hasMeshoptFallback(const json& buffer) {
    const auto ext = buffer.find("extensions");
    return ext != buffer.end() && ext->is_object() &&
           (ext->contains("EXT_meshopt_compression") || ext->contains("KHR_meshopt_compression"));
}

}  // namespace

json parseGltfJson(std::span<const unsigned char> bytes) {
    GlbParts glb;
    const std::string_view text = splitGlb(bytes, glb) ? glb.json : std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    return json::parse(text.begin(), text.end(), nullptr, false);
}

PreparedContainer prepareForParser(std::span<const unsigned char> bytes, json doc) {
    PreparedContainer prepared;
    GlbParts glb;
    const bool isGlb = splitGlb(bytes, glb);
    if (doc.is_discarded() || !doc.is_object()) return prepared;

    bool changed = false;
    json* accessors = doc.contains("accessors") && doc["accessors"].is_array() ? &doc["accessors"] : nullptr;
    json* buffers = doc.contains("buffers") && doc["buffers"].is_array() ? &doc["buffers"] : nullptr;
    if (accessors) prepared.rewrites.accessorHasNoView.assign(accessors->size(), false);
    if (buffers) prepared.rewrites.bufferIsPlaceholder.assign(buffers->size(), false);

    if (buffers)
        for (std::size_t k = 0; k < buffers->size(); ++k) {
            json& b = (*buffers)[k];
            if (!b.is_object() || b.contains("uri") || !hasMeshoptFallback(b)) continue;
            if (isGlb && k == 0 && glb.hasBinChunk) continue;  // the binary chunk is buffer 0's data
            b["uri"] = kStandInUri;
            b["byteLength"] = 4;
            prepared.rewrites.bufferIsPlaceholder[k] = true;
            changed = true;
        }

    std::size_t standInView = 0;
    bool haveStandIn = false;
    if (accessors)
        for (std::size_t i = 0; i < accessors->size(); ++i) {
            json& a = (*accessors)[i];
            if (!a.is_object() || a.contains("bufferView")) continue;
            if (!haveStandIn) {
                if (!doc.contains("buffers")) doc["buffers"] = json::array();
                if (!doc.contains("bufferViews")) doc["bufferViews"] = json::array();
                if (!doc["buffers"].is_array() || !doc["bufferViews"].is_array()) return PreparedContainer{};
                doc["buffers"].push_back({{"uri", kStandInUri}, {"byteLength", 4}});
                doc["bufferViews"].push_back({{"buffer", doc["buffers"].size() - 1}, {"byteLength", 4}});
                standInView = doc["bufferViews"].size() - 1;
                prepared.rewrites.bufferIsPlaceholder.resize(doc["buffers"].size(), false);
                prepared.rewrites.bufferIsPlaceholder.back() = true;
                haveStandIn = true;
            }
            a["bufferView"] = standInView;
            a.erase("byteOffset");
            prepared.rewrites.accessorHasNoView[i] = true;
            changed = true;
        }

    if (!changed) return prepared;
    const std::string rewritten = doc.dump();
    prepared.bytes = isGlb ? joinGlb(rewritten, glb.rest) : std::vector<unsigned char>(rewritten.begin(), rewritten.end());
    return prepared;
}

}  // namespace dacrt::gltf
