#include "cmd/info.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <dacrt/scene_info.hpp>

#include "app/exit_codes.hpp"

namespace dacrt {
namespace {

std::string vec(const std::array<double, 3>& v) {
    char s[96];
    std::snprintf(s, sizeof s, "(%.6g, %.6g, %.6g)", v[0], v[1], v[2]);
    return s;
}

std::string vec(const std::array<float, 3>& v) { return vec(std::array<double, 3>{v[0], v[1], v[2]}); }

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

std::string cameraLine(const PlacedCamera& c) {
    char lens[64];
    if (c.perspective) std::snprintf(lens, sizeof lens, "perspective, yfov %.4g degrees", c.yfovRadians * 180.0 / M_PI);
    else std::snprintf(lens, sizeof lens, "orthographic, ymag %.6g", c.ymag);
    return std::to_string(c.index) + (c.name.empty() ? "" : " '" + c.name + "'") + ": " + lens + ", node " +
           std::to_string(c.node) + ", eye " + vec(c.eye) + ", forward " + vec(c.forward);
}

std::string lightLine(const PlacedLight& l) {
    return (l.name.empty() ? std::string("(unnamed)") : "'" + l.name + "'") + ": " + l.type + ", intensity " +
           number(l.intensity) + ", colour " + vec(l.color) + (l.type == "directional" ? "" : ", at " + vec(l.position)) +
           (l.type == "point" ? "" : ", towards " + vec(l.direction));
}

std::string animationLine(std::size_t index, const AnimationSpan& a) {
    return std::to_string(index) + (a.name.empty() ? "" : " '" + a.name + "'") + ": " + number(a.start) + " s to " +
           number(a.end) + " s, " + std::to_string(a.channels) + " channel(s)";
}

template <typename Item, typename Line>
std::vector<std::string> linesOf(const std::vector<Item>& items, Line line) {
    std::vector<std::string> out;
    for (const Item& i : items) out.push_back(line(i));
    return out;
}

}  // namespace

int runInfo(const InfoOptions& options) {
    const SceneFileInfo info = describeSceneFile(options.scenePath, options.sceneChoice);
    std::cout << "file " << options.scenePath << "\n";
    section("scenes", info.scenes);
    std::cout << "loaded scene: " << info.triangles << " triangles (" << info.singleSidedTriangles << " single-sided, "
              << info.trianglesDropped << " without area dropped), bounds " << vec(info.bounds.lo) << " to "
              << vec(info.bounds.hi) << "\n";
    std::cout << "  shading: " << (info.normals ? "NORMAL" : "geometric normals") << (info.texCoords ? ", texture coordinates" : "")
              << (info.colors ? ", COLOR_0" : "") << "\n";
    section("cameras placed by the scene (--camera)", linesOf(info.cameras, cameraLine));
    section("lights placed by the scene (KHR_lights_punctual)", linesOf(info.lights, lightLine));
    std::vector<std::string> animations;
    for (std::size_t i = 0; i < info.animations.size(); ++i) animations.push_back(animationLine(i, info.animations[i]));
    section("animations (--animation; all play together by default; the scene above is at 0 s)", animations);
    section("meshes", info.meshes);
    section("skins", info.skins);
    section("materials", info.materials);
    section("textures decoded", info.textures);
    std::cout << "extensions used: " << join(info.extensionsUsed) << "\n"
              << "extensions required: " << join(info.extensionsRequired) << "\n";
    section("warnings", info.warnings);
    return int(kExitSuccess);
}

}  // namespace dacrt
