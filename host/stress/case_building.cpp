#include "stress/case_building.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/camera.hpp"

namespace dacrt::stress {

std::string number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    return text;
}

std::vector<Triangle> trianglesOf(const std::vector<Mesh>& meshes) {
    std::vector<Triangle> out;
    for (const Mesh& m : meshes)
        for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
            out.push_back(Triangle{m.positions[m.indices[i]], 0u, m.positions[m.indices[i + 1]], 0.0f,
                                   m.positions[m.indices[i + 2]], 0.0f});
    return out;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> edgesOf(const Mesh& m) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
        for (int e = 0; e < 3; ++e) edges.insert(std::minmax(m.indices[i + e], m.indices[i + (e + 1) % 3]));
    return {edges.begin(), edges.end()};
}

void RayFan::towards(const glm::dvec3& target) {
    const glm::dvec3 d = target - glm::dvec3(origin_);
    if (glm::length(d) == 0.0) return;  // a target at the origin gives no direction
    along(d);
}

void RayFan::along(const glm::dvec3& direction) {
    const Ray r = makeRay(origin_, direction);
    case_.rays.push_back(r);
    case_.mustHit.push_back(inside_ || certainlyEntersBall(r) ? 1 : 0);
}

bool RayFan::certainlyEntersBall(const Ray& r) const {
    if (!balls_) return false;
    const glm::dvec3 o(r.origin), d(r.dir);
    for (const Ball& b : *balls_) {
        const double t = glm::dot(b.centre - o, d) / glm::dot(d, d);
        if (t <= 0.0) continue;
        if (glm::length(o + t * d - b.centre) < 0.8 * b.radius) return true;
    }
    return false;
}

// The room [-1, 1]^3: every ray from inside it must hit something.
Mesh room() { return box({-1, -1, -1}, {1, 1, 1}); }

// Grids in the planes the spatial-median splits and the region slabs of the room use
// (x = 0, y = 0, z = 0, then +-0.5, +-0.25, ...), with vertices on dyadic coordinates so
// that they fall exactly on cell boundaries. Each covers part of its plane only.
std::vector<Mesh> splitPlaneGrids() {
    return {grid({0.0f, -1.0f, -0.5f}, {0, 1.5f, 0}, {0, 0, 1.5f}, 6, 6),
            grid({-1.0f, 0.0f, -1.0f}, {1.5f, 0, 0}, {0, 0, 1.0f}, 12, 8),
            grid({-0.5f, -0.5f, 0.0f}, {1.5f, 0, 0}, {0, 1.5f, 0}, 6, 12),
            grid({0.5f, -1.0f, -1.0f}, {0, 2.0f, 0}, {0, 0, 0.75f}, 8, 3),
            grid({-1.0f, -0.5f, -1.0f}, {0.75f, 0, 0}, {0, 0, 2.0f}, 3, 8),
            grid({-1.0f, -1.0f, 0.25f}, {1.0f, 0, 0}, {0, 1.0f, 0}, 4, 4),
            grid({0.0f, 0.0f, -0.75f}, {1.0f, 0, 0}, {0, 1.0f, 0}, 8, 8)};
}

std::vector<Mesh> roomWithShapes() {
    std::vector<Mesh> m = {room(), icosphere({0.5f, 0.5f, -0.5f}, 0.3f, 2),
                           torus({-0.5f, -0.25f, 0.5f}, 0.3f, 0.1f, 24, 12),
                           box({0.25f, -0.75f, 0.25f}, {0.75f, -0.25f, 0.75f}),
                           cylinder({-0.5f, -1.0f, -0.5f}, 0.05f, 2.0f, 12, 8)};
    for (Mesh& g : splitPlaneGrids()) m.push_back(g);
    return m;
}

// Pinhole rays of an odd-sized image, so that the centre row and column have exactly zero
// components: they travel inside the planes through the camera.
void addPinhole(RayFan& fan, const glm::dvec3& forward, const glm::dvec3& up, int width, int height, double fovDegrees) {
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const double tanHalf = std::tan(0.5 * glm::radians(fovDegrees));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double sx = (2.0 * (x + 0.5) / width - 1.0) * tanHalf * double(width) / height;
            const double sy = (1.0 - 2.0 * (y + 0.5) / height) * tanHalf;
            fan.along(forward + sx * right + sy * up);
        }
}

}  // namespace dacrt::stress
