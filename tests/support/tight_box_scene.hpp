#pragma once
// A scene for the tight node boxes (docs/correctness.md, "Tight node boxes"): small boxes far
// apart in a large scene box (two specks at its corners), so that a node's box shrinks to its
// triangles' bounds by far, and rays whose hits lie on those bounds' faces. Rays aim at the
// clusters' corners, edge midpoints and face centres from all around; others travel inside the
// planes of the bounds' faces. A shrunk box taken without either widening (the bounds' and the
// filter's), or made from fewer triangles than the node's, loses some of these hits.
#include <cmath>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/procedural.hpp"
#include "core/random.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt::test {

struct TightBoxScene {
    std::vector<Mesh> meshes;
    std::vector<Ray> rays;  // each with its own origin
    glm::dvec3 cameraEye{0.5, 0.3, 9.0};  // a camera at it, looking at the origin, sees every cluster
};

inline TightBoxScene tightBoxScene() {
    TightBoxScene s;
    s.meshes.push_back(grid({-4, -4, -4}, {0.01f, 0, 0}, {0, 0.01f, 0}, 1, 1));
    s.meshes.push_back(grid({4, 4, 4}, {-0.01f, 0, 0}, {0, 0, -0.01f}, 1, 1));
    const std::vector<std::pair<glm::vec3, glm::vec3>> clusters = {
        {{-3.0f, -2.5f, -1.0f}, {-2.5f, -2.0f, -0.75f}}, {{1.0f, 2.0f, 3.0f}, {1.25f, 2.5f, 3.25f}},
        {{2.5f, -3.0f, 0.5f}, {3.0f, -2.875f, 1.0f}},   {{-0.5f, 0.25f, -3.5f}, {0.0f, 0.75f, -3.0f}}};
    std::vector<glm::vec3> targets;
    for (const auto& [lo, hi] : clusters) {
        s.meshes.push_back(box(lo, hi));
        s.meshes.push_back(doubleSided(grid(lo, {hi.x - lo.x, 0, 0}, {0, hi.y - lo.y, 0}, 2, 2)));  // on its low z face
        for (int i = 0; i <= 2; ++i)
            for (int j = 0; j <= 2; ++j)
                for (int k = 0; k <= 2; ++k)
                    if (i != 1 || j != 1 || k != 1)  // corners, edge midpoints and face centres
                        targets.push_back(lo + (hi - lo) * glm::vec3(float(i), float(j), float(k)) * 0.5f);
    }
    Random random(41);
    for (const glm::vec3& target : targets)
        for (int n = 0; n < 12; ++n) {
            const glm::vec3 from = target + 3.0f * glm::vec3(random.onSphere());
            s.rays.push_back(makeRay(from, glm::dvec3(target) - glm::dvec3(from)));
        }
    for (const auto& [lo, hi] : clusters)
        for (int n = 0; n < 16; ++n) {
            const double a = 0.4 * double(n);
            const float f = float(n) / 15.0f;
            s.rays.push_back(makeRay({lo.x - 1.0f, lo.y, lo.z + 0.01f * float(n)}, {1.0, 0.0, 0.1 * std::sin(a)}));  // in y = lo.y
            s.rays.push_back(makeRay({hi.x, hi.y + 1.0f, lo.z + (hi.z - lo.z) * f}, {0.0, -1.0, 0.1 * std::sin(a)}));  // in x = hi.x
            s.rays.push_back(makeRay({lo.x + (hi.x - lo.x) * f, hi.y, hi.z + 1.0f}, {0.0, 0.0, -1.0}));  // down the face y = hi.y
        }
    return s;
}

}  // namespace dacrt::test
