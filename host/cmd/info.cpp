#include "cmd/info.hpp"

#include <cstdio>
#include <iostream>

#include "app/exit_codes.hpp"
#include "core/gltf_loader.hpp"

namespace dacrt {
namespace {

std::string vec(const glm::dvec3& v) {
    char s[96];
    std::snprintf(s, sizeof s, "(%.6g, %.6g, %.6g)", v.x, v.y, v.z);
    return s;
}

std::string number(double x) {
    char s[32];
    std::snprintf(s, sizeof s, "%.6g", x);
    return s;
}

void section(const char* title, const std::vector<std::string>& lines) {
    std::cout << title << " (" << lines.size() << ")\n";
    for (const std::string& l : lines) std::cout << "  " << l << "\n";
}

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& i : items) out += (out.empty() ? "" : ", ") + i;
    return out.empty() ? "none" : out;
}

}  // namespace

int runInfo(const InfoOptions& options) {
    const GltfDocument file = GltfDocument::open(options.scenePath);
    const Scene scene = file.scene(GltfSelection{.scene = options.sceneChoice, .animation = "", .time = 0.0});
    const GltfInventory& inv = scene.inventory;
    const Box box = sceneBounds(scene.triangles);
    std::cout << "file " << options.scenePath << "\n";
    section("scenes", inv.scenes);
    std::cout << "loaded scene: " << scene.triangleCount() << " triangles (" << singleSidedTriangles(scene.triangles)
              << " single-sided, " << scene.degenerateTrianglesDropped << " without area dropped), bounds "
              << vec(glm::dvec3(box.lo)) << " to " << vec(glm::dvec3(box.hi)) << "\n";
    std::cout << "  shading: " << (scene.corners.normals.empty() ? "geometric normals" : "NORMAL")
              << (scene.corners.texCoords.empty() ? "" : ", texture coordinates")
              << (scene.corners.colors.empty() ? "" : ", COLOR_0") << "\n";
    std::vector<std::string> cameras;
    for (const SceneCamera& c : scene.cameras) {
        char lens[64];
        if (c.projection == Projection::Perspective) std::snprintf(lens, sizeof lens, "perspective, yfov %.4g degrees", c.yfovRadians * 180.0 / M_PI);
        else std::snprintf(lens, sizeof lens, "orthographic, ymag %.6g", c.ymag);
        cameras.push_back(std::to_string(c.cameraIndex) + (c.name.empty() ? "" : " '" + c.name + "'") + ": " + lens +
                          ", node " + std::to_string(c.node) + ", eye " + vec(c.eye) + ", forward " + vec(c.forward));
    }
    section("cameras placed by the scene (--camera)", cameras);
    std::vector<std::string> lights;
    for (const Light& l : scene.lights)
        lights.push_back((l.name.empty() ? std::string("(unnamed)") : "'" + l.name + "'") + ": " + std::string(toString(l.type)) +
                         ", intensity " + number(l.intensity) + ", colour " + vec(glm::dvec3(l.color)) +
                         (l.type == LightType::Directional ? "" : ", at " + vec(l.position)) +
                         (l.type == LightType::Point ? "" : ", towards " + vec(l.direction)));
    section("lights placed by the scene (KHR_lights_punctual)", lights);
    std::vector<std::string> animations;
    for (std::size_t i = 0; i < file.animations().size(); ++i) {
        const GltfAnimationInfo& a = file.animations()[i];
        animations.push_back(std::to_string(i) + (a.name.empty() ? "" : " '" + a.name + "'") + ": " + number(a.start) + " s to " +
                             number(a.end) + " s, " + std::to_string(a.channels) + " channel(s)");
    }
    section("animations (--animation; all play together by default; the scene above is at 0 s)", animations);
    section("meshes", inv.meshes);
    section("skins", inv.skins);
    section("materials", inv.materials);
    section("textures decoded", inv.textures);
    std::cout << "extensions used: " << join(inv.extensionsUsed) << "\n"
              << "extensions required: " << join(inv.extensionsRequired) << "\n";
    section("warnings", scene.warnings);
    return int(kExitSuccess);
}

}  // namespace dacrt
