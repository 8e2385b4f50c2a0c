// The public describeSceneFile: a glTF file's inventory and its loaded scene, as `dacrt info`
// prints them.
#include <tuple>

#include <dacrt/scene_info.hpp>

#include "core/gltf_loader.hpp"

namespace dacrt {
namespace {

std::array<double, 3> publicVector(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

PlacedCamera placedCamera(const SceneCamera& c) {
    return {.index = c.cameraIndex,
            .name = c.name,
            .perspective = c.projection == Projection::Perspective,
            .yfovRadians = c.yfovRadians,
            .ymag = c.ymag,
            .node = c.node,
            .eye = publicVector(c.eye),
            .forward = publicVector(c.forward)};
}

PlacedLight placedLight(const Light& l) {
    return {.name = l.name,
            .type = std::string(toString(l.type)),
            .intensity = l.intensity,
            .color = publicVector(glm::dvec3(l.color)),
            .position = publicVector(l.position),
            .direction = publicVector(l.direction)};
}

// The loaded scene's triangles, bounds and shading attributes.
void describeLoadedScene(const Scene& scene, SceneFileInfo& info) {
    const Box box = sceneBounds(scene.triangles);
    info.triangles = scene.triangleCount();
    info.singleSidedTriangles = singleSidedTriangles(scene.triangles);
    info.trianglesDropped = scene.degenerateTrianglesDropped;
    info.bounds = {.lo = {box.lo.x, box.lo.y, box.lo.z}, .hi = {box.hi.x, box.hi.y, box.hi.z}};
    info.normals = !scene.corners.normals.empty();
    info.texCoords = !scene.corners.texCoords.empty();
    info.colors = !scene.corners.colors.empty();
    for (const SceneCamera& c : scene.cameras) info.cameras.push_back(placedCamera(c));
    for (const Light& l : scene.lights) info.lights.push_back(placedLight(l));
    info.warnings = scene.warnings;
}

}  // namespace

SceneFileInfo describeSceneFile(const std::string& path, const std::string& sceneChoice) {
    const GltfDocument file = GltfDocument::open(path);
    const Scene scene = file.scene(GltfSelection{.scene = sceneChoice, .animation = "", .time = 0.0});
    const GltfInventory& inventory = scene.inventory;
    SceneFileInfo info;
    std::tie(info.scenes, info.meshes, info.skins, info.materials, info.textures, info.extensionsUsed,
             info.extensionsRequired) = std::tie(inventory.scenes, inventory.meshes, inventory.skins, inventory.materials,
                                                 inventory.textures, inventory.extensionsUsed, inventory.extensionsRequired);
    describeLoadedScene(scene, info);
    for (const GltfAnimationInfo& a : file.animations())
        info.animations.push_back({.name = a.name, .start = a.start, .end = a.end, .channels = a.channels});
    return info;
}

}  // namespace dacrt
