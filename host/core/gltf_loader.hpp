#pragma once
// The load stage: a glTF 2.0 file's default scene flattened into world-space triangles.
#include <cstdint>
#include <span>
#include <string>

#include "core/scene.hpp"

namespace dacrt {

struct GltfLimits {
    std::uint64_t maxBytes = 0;            // memory the flattened scene may take; 0: this machine's memory
    std::uint32_t maxHierarchyDepth = 1024;  // node levels below a scene's root
    std::uint32_t maxJsonNesting = 256;      // objects and arrays inside one another, checked before parsing
};

// Which of the file's scenes to load: an index or a name; empty: the file's default scene.
struct GltfSelection {
    std::string scene;
};

// Loads the default scene of a glTF 2.0 file (.gltf or .glb) and flattens every triangle
// primitive into world space, dropping triangles with no area (counted in
// Scene::degenerateTrianglesDropped). Bad files throw InputError naming the file and the
// problem, before anything large is allocated (docs/gltf-input.md lists the rules).
Scene loadGltf(const std::string& path, const GltfLimits& limits = {}, const GltfSelection& selection = {});

// The same from bytes in memory (a .glb, or the text of a .gltf); `name` stands for the file in
// messages. External files (buffers by uri) are never read from memory input: only embedded
// data URIs and the .glb binary chunk.
Scene loadGltfFromMemory(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits = {},
                         const GltfSelection& selection = {});

// Makes scene.camera the placed camera whose glTF name is `choice`, or else whose camera index
// it is; empty: keeps the first placed. Throws InputError listing the cameras when none matches.
void selectCamera(Scene& scene, const std::string& choice);

}  // namespace dacrt
