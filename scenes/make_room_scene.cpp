// Generates scenes/room.glb, the default scene: a room (floor, walls, ceiling) holding a few
// tessellated objects, with a camera. Run: build/make_room_scene scenes/room.glb
#include <iostream>

#include "core/errors.hpp"
#include "core/procedural.hpp"

int main(int argc, char** argv) {
    using namespace dacrt;
    if (argc != 2) {
        std::cerr << "usage: make_room_scene OUT.glb\n";
        return 2;
    }
    auto colored = [](Mesh m, const std::string& name, glm::vec4 c) {
        m.name = name;
        m.color = c;
        return m;
    };
    const float w = 4.0f, h = 2.6f, d = 4.0f;  // room from (-2, 0, -2) to (2, 2.6, 2)
    std::vector<Mesh> meshes = {
        colored(grid({-w / 2, 0, d / 2}, {w, 0, 0}, {0, 0, -d}, 16, 16), "floor", {0.55f, 0.5f, 0.45f, 1}),
        colored(grid({-w / 2, h, -d / 2}, {w, 0, 0}, {0, 0, d}, 8, 8), "ceiling", {0.9f, 0.9f, 0.9f, 1}),
        colored(grid({-w / 2, 0, -d / 2}, {w, 0, 0}, {0, h, 0}, 16, 10), "back wall", {0.75f, 0.75f, 0.7f, 1}),
        colored(grid({-w / 2, 0, d / 2}, {0, 0, -d}, {0, h, 0}, 16, 10), "left wall", {0.7f, 0.25f, 0.2f, 1}),
        colored(grid({w / 2, 0, -d / 2}, {0, 0, d}, {0, h, 0}, 16, 10), "right wall", {0.2f, 0.35f, 0.7f, 1}),
        colored(icosphere({-0.9f, 0.55f, -0.6f}, 0.55f, 4), "sphere", {0.85f, 0.75f, 0.3f, 1}),
        colored(torus({0.8f, 0.35f, 0.3f}, 0.5f, 0.18f, 64, 24), "torus", {0.3f, 0.7f, 0.4f, 1}),
        colored(cylinder({0.9f, 0.0f, -1.1f}, 0.3f, 1.6f, 48, 8), "column", {0.8f, 0.8f, 0.85f, 1}),
        colored(box({-0.3f, 0.0f, 0.5f}, {0.2f, 0.5f, 1.0f}), "crate", {0.6f, 0.4f, 0.25f, 1}),
        colored(icosphere({-0.05f, 0.72f, 0.75f}, 0.22f, 3), "small sphere", {0.75f, 0.3f, 0.6f, 1}),
    };
    SceneCamera camera;
    camera.eye = {0.0, 1.35, 1.95};
    camera.forward = glm::normalize(glm::dvec3(0.0, -0.3, -1.0));
    camera.up = glm::normalize(glm::cross(glm::cross(camera.forward, glm::dvec3(0, 1, 0)), camera.forward));
    camera.yfovRadians = glm::radians(70.0);
    try {
        writeGltf(argv[1], meshes, camera);
    } catch (const InputError& e) {
        std::cerr << e.what() << "\n";
        return 2;
    }
    std::size_t triangles = 0;
    for (const Mesh& m : meshes) triangles += m.indices.size() / 3;
    std::cout << "wrote " << argv[1] << ": " << triangles << " triangles\n";
    return 0;
}
