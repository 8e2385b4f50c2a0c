#pragma once
// What the stress case families share: balls known to lie inside closed meshes, ray fans
// that mark must-hit rays, the room with its split-plane grids, pinhole fans.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "stress/stress_cases.hpp"
#include "core/procedural.hpp"

namespace dacrt::stress {

// A ball that lies inside a closed mesh: a ray that starts outside the mesh and reaches the
// ball at t > 0 must cross the surface on the way.
struct Ball {
    glm::dvec3 centre;
    double radius;
};

std::string number(double x);
std::vector<Triangle> trianglesOf(const std::vector<Mesh>& meshes);
std::vector<std::pair<std::uint32_t, std::uint32_t>> edgesOf(const Mesh& m);

// Builds the case's rays from one origin towards targets (points) and along directions.
// mustHit marks every ray when the origin lies inside a closed surface; otherwise only
// rays whose line passes well inside one of the balls at t > 0.
class RayFan {
public:
    RayFan(StressCase& c, const glm::vec3& origin, bool originInside, const std::vector<Ball>* balls = nullptr)
        : case_(c), origin_(origin), inside_(originInside), balls_(balls) {}

    void towards(const glm::dvec3& target);
    void along(const glm::dvec3& direction);

private:
    bool certainlyEntersBall(const Ray& r) const;

    StressCase& case_;
    glm::vec3 origin_;
    bool inside_;
    const std::vector<Ball>* balls_;
};

// The room [-1, 1]^3: every ray from inside it must hit something.
Mesh room();
// Grids in the planes the spatial-median splits and the region slabs of the room use.
std::vector<Mesh> splitPlaneGrids();
std::vector<Mesh> roomWithShapes();
// Pinhole rays of an odd-sized image, so that the centre row and column have exactly zero
// components: they travel inside the planes through the camera.
void addPinhole(RayFan& fan, const glm::dvec3& forward, const glm::dvec3& up, int width, int height,
                double fovDegrees = 70.0);

}  // namespace dacrt::stress
