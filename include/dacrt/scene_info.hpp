#pragma once
// What a glTF file holds, as `dacrt info` prints it: its scenes, the chosen scene's triangles,
// bounds and shading attributes, and the cameras, lights, animations, meshes, skins,
// materials, textures and extensions it brings.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <dacrt/scene.hpp>

namespace dacrt {

struct PlacedCamera {
    std::int32_t index = -1;  // in the file's cameras (what --camera takes)
    std::string name;         // the glTF camera's; may be empty
    bool perspective = true;  // else orthographic
    double yfovRadians = 0.0; // perspective: the vertical field of view
    double ymag = 0.0;        // orthographic: half the view's height
    std::int32_t node = -1;   // the node that places it
    std::array<double, 3> eye{};
    std::array<double, 3> forward{};  // unit
};

struct PlacedLight {
    std::string name;        // may be empty
    std::string type;        // "point", "spot" or "directional"
    double intensity = 0.0;  // candela (point, spot) or lux (directional)
    std::array<double, 3> color{};
    std::array<double, 3> position{};   // point, spot
    std::array<double, 3> direction{};  // spot, directional: where the light travels, unit
};

struct AnimationSpan {
    std::string name;    // may be empty
    double start = 0.0;  // seconds
    double end = 0.0;
    std::uint64_t channels = 0;
};

struct SceneFileInfo {
    std::vector<std::string> scenes;  // "0 'name': K root node(s)", the loaded one marked
    // The loaded scene at 0 s, flattened as TraceScene::load flattens it.
    std::uint64_t triangles = 0;             // with area, traced
    std::uint64_t singleSidedTriangles = 0;  // of those, the ones whose back faces no ray hits
    std::uint64_t trianglesDropped = 0;      // without area, dropped
    SceneBounds bounds;                      // of the traced triangles, exact
    bool normals = false;    // NORMAL shades (else the geometric normals)
    bool texCoords = false;  // texture coordinates
    bool colors = false;     // COLOR_0
    std::vector<PlacedCamera> cameras;      // placed by the loaded scene's nodes, in node order
    std::vector<PlacedLight> lights;        // KHR_lights_punctual, placed by the loaded scene's nodes
    std::vector<AnimationSpan> animations;  // the file's, by index (what --animation takes)
    // What the file holds, one line each.
    std::vector<std::string> meshes;     // with primitives and triangles
    std::vector<std::string> skins;      // with joints and the nodes they deform
    std::vector<std::string> materials;
    std::vector<std::string> textures;   // those decoded
    std::vector<std::string> extensionsUsed;
    std::vector<std::string> extensionsRequired;
    std::vector<std::string> warnings;   // what the loader ignored
};

// The file at `path` (.gltf or .glb) with its scene `sceneChoice` (an index or a name; empty:
// the file's default) loaded at 0 s. Throws InputError naming the file and the problem.
SceneFileInfo describeSceneFile(const std::string& path, const std::string& sceneChoice = "");

}  // namespace dacrt
