#pragma once
// What tinygltf 2.7 refuses although glTF 2.0 allows it, made parseable before it parses and
// remembered for the reader: accessors without a bufferView (all zeros unless sparse, or
// decoded by KHR_draco_mesh_compression) and buffers without data (EXT_meshopt_compression's
// fallback buffers). Internal to the glTF loader.
#include <span>
#include <string>
#include <vector>

namespace dacrt::gltf {

struct ContainerRewrites {
    std::vector<bool> accessorHasNoView;    // by accessor index; such accessors point at a stand-in view
    std::vector<bool> bufferIsPlaceholder;  // by buffer index; no bytes of it may be read
};

struct PreparedContainer {
    std::vector<unsigned char> bytes;  // the rewritten file; empty when nothing needed rewriting
    ContainerRewrites rewrites;
};

// bytes: a .glb or the text of a .gltf whose JSON parses (anything else is left for the parser
// to refuse: nothing is rewritten).
PreparedContainer prepareForParser(std::span<const unsigned char> bytes);

}  // namespace dacrt::gltf
