#pragma once
// Procedural meshes for the shipped default scene and the tests, and a glTF writer for them.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene.hpp"

namespace dacrt {

struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<std::uint32_t> indices;  // three per triangle
    glm::vec4 color{0.8f, 0.8f, 0.8f, 1.0f};
    bool doubleSided = false;  // its material's (glTF's default: single-sided)
};

// The mesh with a double-sided material: seen from both sides (a closed mesh from inside).
inline Mesh doubleSided(Mesh m) {
    m.doubleSided = true;
    return m;
}

Mesh icosphere(const glm::vec3& centre, float radius, int subdivisions);
Mesh torus(const glm::vec3& centre, float majorRadius, float minorRadius, int majorSegments, int minorSegments);
Mesh box(const glm::vec3& lo, const glm::vec3& hi);  // two triangles per face, outward winding
Mesh cylinder(const glm::vec3& baseCentre, float radius, float height, int segments, int rings);
// A rectangle corner, corner + edgeU, corner + edgeU + edgeV, corner + edgeV cut into a
// segmentsU x segmentsV grid of quads.
Mesh grid(const glm::vec3& corner, const glm::vec3& edgeU, const glm::vec3& edgeV, int segmentsU, int segmentsV);

// One mesh per glTF mesh, in order; provenance and materials as the loader would produce.
Scene sceneFromMeshes(const std::vector<Mesh>& meshes, const std::string& name = "procedural");

// Writes a glTF 2.0 file (binary when the name ends in .glb) with one node per mesh and,
// if given, a perspective camera node.
void writeGltf(const std::string& path, const std::vector<Mesh>& meshes, const std::optional<SceneCamera>& camera);

}  // namespace dacrt
