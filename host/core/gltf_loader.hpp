#pragma once
// The load stage: a glTF 2.0 file's scene flattened into world-space triangles, at an instant of
// its animations.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/scene.hpp"

namespace dacrt {

struct GltfLimits {
    std::uint64_t maxBytes = 0;            // memory the flattened scene may take; 0: this machine's memory
    std::uint32_t maxHierarchyDepth = 1024;  // node levels below a scene's root
    std::uint32_t maxJsonNesting = 256;      // objects and arrays inside one another, checked before parsing
};

// Which of the file's scenes to load, and when: an index or a name; empty: the file's default
// scene. Animations (node translation, rotation, scale and morph-target weights) are sampled
// at `time` seconds: every animation of the file together, or the one `animation` names (an
// index or a name). Skins and morph targets always deform their meshes, animated or not.
struct GltfSelection {
    std::string scene;
    std::string animation;  // empty: every animation together
    double time = 0.0;      // seconds; before an animation's first key it holds the first key's value
};

// An animation of the file: its name, its keys' time span (seconds) and its channels.
struct GltfAnimationInfo {
    std::string name;
    double start = 0.0;
    double end = 0.0;
    std::size_t channels = 0;
};

// A glTF file parsed and checked once, its scenes flattened at any instant: what a frame range
// loads once and evaluates per frame. The accessors' data are read once and kept.
class GltfDocument {
public:
    static GltfDocument open(const std::string& path, const GltfLimits& limits = {});
    static GltfDocument fromMemory(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits = {});
    GltfDocument(GltfDocument&&) noexcept;
    GltfDocument& operator=(GltfDocument&&) noexcept;
    ~GltfDocument();

    // The flattened scene (as loadGltf describes) at the selection's instant. Throws InputError
    // for a scene or animation that does not exist, or an animation that cannot be sampled.
    // onProgress, when given, is called on the calling thread after each primitive instance
    // with the fraction of the planned triangles assembled (a large scene takes seconds).
    Scene scene(const GltfSelection& selection = {}, const std::function<void(double)>& onProgress = {}) const;

    // The threads that place the vertices and assemble the triangles (0: every core, the
    // default). The scene is the same for any number, bit for bit.
    void setThreads(unsigned threads);

    const std::vector<GltfAnimationInfo>& animations() const;

    // Throws InputError listing the animations when `choice` (an index or a name) names none;
    // empty names every animation.
    void checkAnimationChoice(const std::string& choice) const;

    struct Impl;  // the loader's own (gltf_loader.cpp)
    explicit GltfDocument(std::unique_ptr<Impl> impl);

private:
    std::unique_ptr<Impl> impl_;
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
