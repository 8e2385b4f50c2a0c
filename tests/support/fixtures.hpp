#pragma once
// Scenes for the tests: the tiny fixtures beside them, the shared Stanford models (skipped
// with a message where ../shared is absent), and a procedural shapes scene.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/procedural.hpp"
#include "core/scene.hpp"

namespace dacrt::test {

inline std::string fixture(const std::string& name) { return std::string(DACRT_TEST_SCENES) + "/" + name; }

// Path of a model in ../shared/scenes, or "" when that folder is absent (a fresh clone).
inline std::string sharedScene(const std::string& name) {
    const std::string path = std::string(DACRT_SHARED_SCENES) + "/" + name;
    return std::filesystem::exists(path) ? path : std::string();
}

#define DACRT_REQUIRE_SHARED_SCENE(var, name)                                                       \
    const std::string var = ::dacrt::test::sharedScene(name);                                       \
    if (var.empty()) GTEST_SKIP() << "../shared/scenes/" << name << " is absent (fresh clone): skipped"

// Sphere, torus, box and cylinder on a floor: shared edges, silhouettes and occlusion.
inline std::vector<Mesh> shapesMeshes() {
    Mesh floor = grid({-2, -1, 2}, {4, 0, 0}, {0, 0, -4}, 12, 12);
    return {icosphere({-0.8f, 0.0f, 0.0f}, 0.7f, 3), torus({0.9f, -0.2f, 0.3f}, 0.6f, 0.2f, 40, 16),
            box({-0.3f, -1.0f, -1.2f}, {0.4f, 0.6f, -0.6f}), cylinder({1.2f, -1.0f, -1.0f}, 0.3f, 1.5f, 24, 4), floor};
}
inline Scene shapesScene() { return sceneFromMeshes(shapesMeshes(), "shapes"); }

// The shapes and a finely divided sphere among them (20 * 4^subdivisions triangles of it):
// secondary passes of fewer rays than triangles, as the Dragon's.
inline Scene shapesAndDenseSphere(int subdivisions) {
    std::vector<Mesh> meshes = shapesMeshes();
    meshes.push_back(icosphere({0.6f, 0.3f, 0.9f}, 0.35f, subdivisions));
    return sceneFromMeshes(meshes, "shapes and a dense sphere");
}

}  // namespace dacrt::test
