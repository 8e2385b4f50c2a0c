#pragma once
// What tinygltf 2.7 refuses although glTF 2.0 allows it, made parseable before it parses and
// remembered for the reader: accessors without a bufferView (all zeros unless sparse, or
// decoded by KHR_draco_mesh_compression) and buffers without data (EXT_meshopt_compression's
// fallback buffers). Internal to the glTF loader.
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace dacrt::gltf {

struct ContainerRewrites {
    std::vector<bool> accessorHasNoView;    // by accessor index; such accessors point at a stand-in view
    std::vector<bool> bufferIsPlaceholder;  // by buffer index; no bytes of it may be read
};

struct PreparedContainer {
    std::vector<unsigned char> bytes;  // the rewritten file; empty when nothing needed rewriting
    ContainerRewrites rewrites;
};

// The JSON of a .glb (its first chunk, when the header is consistent) or of a .gltf's text;
// discarded when it does not parse (the parser then says why).
nlohmann::json parseGltfJson(std::span<const unsigned char> bytes);

// bytes: a .glb or the text of a .gltf, and `doc`, its JSON (parseGltfJson); a file whose JSON
// does not parse is left for the parser to refuse: nothing is rewritten.
PreparedContainer prepareForParser(std::span<const unsigned char> bytes, nlohmann::json doc);

}  // namespace dacrt::gltf
