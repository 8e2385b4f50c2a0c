// The stress suite's split-plane family (docs/stability.md).
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "stress/case_building.hpp"
#include "core/camera.hpp"
#include "core/random.hpp"

namespace dacrt {
namespace {

using namespace stress;

std::vector<StressCase> splitPlaneCasesImpl(StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    std::vector<StressCase> out;
    const int width = large ? 129 : 41, height = large ? 97 : 31;

    {
        // Triangles in split planes, seen from points on those planes: the rays to the
        // grids' vertices travel inside the grids' planes.
        std::vector<Mesh> meshes = splitPlaneGrids();
        meshes.insert(meshes.begin(), room());
        const std::vector<Triangle> triangles = trianglesOf(meshes);
        const std::vector<glm::vec3> origins = {{0, 0, 0},       {0, 0.5f, -0.25f}, {0.5f, 0, 0.75f},
                                                {-0.25f, 0.25f, 0}, {0.3f, 0.2f, 0.1f}};
        for (std::size_t k = 0; k < origins.size(); ++k) {
            StressCase c{"split-plane", "planes from " + std::to_string(k), triangles, {}, {}, {}};
            RayFan fan(c, origins[k], true);
            for (const Mesh& m : meshes)
                for (const glm::vec3& p : m.positions) fan.towards(glm::dvec3(p));
            for (int i = 0, n = large ? 4000 : 500; i < n; ++i) fan.along(random.onSphere());
            out.push_back(std::move(c));
        }
    }
    {
        // The camera exactly on split planes and region boundaries, inside the scene,
        // looking along each axis: rays in the planes through it, one axis-parallel ray.
        const std::vector<Triangle> triangles = trianglesOf(roomWithShapes());
        const std::vector<glm::vec3> eyes = {{0, 0, 0}, {0.5f, 0, -0.25f}, {-0.5f, 0.25f, 0}};
        const std::vector<std::pair<glm::dvec3, glm::dvec3>> looks = {
            {{0, 0, -1}, {0, 1, 0}}, {{1, 0, 0}, {0, 1, 0}}, {{0, -1, 0}, {0, 0, 1}}, {{0, 0, 1}, {1, 0, 0}}};
        for (std::size_t e = 0; e < eyes.size(); ++e)
            for (std::size_t l = 0; l < looks.size(); ++l) {
                StressCase c{"split-plane", "camera on planes " + std::to_string(e) + " look " + std::to_string(l),
                             triangles, {}, {}, {}};
                RayFan fan(c, eyes[e], true);
                addPinhole(fan, looks[l].first, looks[l].second, width, height);
                out.push_back(std::move(c));
            }
    }
    {
        // Axis-parallel and nearly axis-parallel rays: every direction whose components come
        // from {0, +-1e-30 (flushed to 0), +-1e-12, +-1e-7, +-1e-3, +-1}.
        const std::vector<Triangle> triangles = trianglesOf(roomWithShapes());
        const std::vector<double> values = {0.0, 1e-30, -1e-30, 1e-12, -1e-12, 1e-7, -1e-7, 1e-3, -1e-3, 1.0, -1.0};
        for (const glm::vec3& origin : {glm::vec3(0.25f, -0.5f, 0.125f), glm::vec3(0, 0, 0)}) {
            StressCase c{"split-plane", "axis-parallel from " + number(origin.x) + "," + number(origin.y) + "," +
                                            number(origin.z),
                         triangles, {}, {}, {}};
            RayFan fan(c, origin, true);
            for (double x : values)
                for (double y : values)
                    for (double z : values)
                        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) >= 1e-3) fan.along({x, y, z});
            out.push_back(std::move(c));
        }
    }
    {
        // Grazing rays over a floor that fills the plane y = 0, from on it and just above it.
        std::vector<Mesh> meshes = {room(), grid({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, 16, 16),
                                    grid({-1.0f, -1.0f, 0.5f}, {2, 0, 0}, {0, 2.0f, 0.001f}, 8, 8)};
        const std::vector<Triangle> triangles = trianglesOf(meshes);
        const int azimuths = large ? 256 : 48;
        for (float height : {0.0f, 1e-6f, 1e-3f}) {
            StressCase c{"split-plane", "grazing at height " + number(height), triangles, {}, {}, {}};
            RayFan fan(c, glm::vec3(0.1f, height, 0.3f), true);
            for (double elevation : {0.0, 1e-7, -1e-7, 1e-6, -1e-6, 1e-5, -1e-5, 1e-4, -1e-4, 1e-3, -1e-3, 1e-2})
                for (int a = 0; a < azimuths; ++a) {
                    const double phi = 2.0 * M_PI * (a + 0.5 * random.uniform()) / azimuths;
                    fan.along({std::cos(phi), elevation, std::sin(phi)});
                }
            for (const glm::vec3& p : meshes[1].positions) fan.towards(glm::dvec3(p));
            out.push_back(std::move(c));
        }
    }
    return out;
}



}  // namespace

std::vector<StressCase> splitPlaneCases(StressSize size, std::uint64_t seed) {
    Random random(seed + 1);
    return splitPlaneCasesImpl(size, random);
}

}  // namespace dacrt
