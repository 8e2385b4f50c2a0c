#pragma once
// Helpers shared by the tests: fixture paths, frames built from scenes, hit comparison.
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "camera.hpp"
#include "cpu_tracers.hpp"
#include "procedural.hpp"
#include "scene.hpp"

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
inline Scene shapesScene() {
    Mesh floor = grid({-2, -1, 2}, {4, 0, 0}, {0, 0, -4}, 12, 12);
    return sceneFromMeshes({icosphere({-0.8f, 0.0f, 0.0f}, 0.7f, 3), torus({0.9f, -0.2f, 0.3f}, 0.6f, 0.2f, 40, 16),
                            box({-0.3f, -1.0f, -1.2f}, {0.4f, 0.6f, -0.6f}), cylinder({1.2f, -1.0f, -1.0f}, 0.3f, 1.5f, 24, 4),
                            floor},
                           "shapes");
}

// A scene, its bounds and one camera's rays: everything a tracer reads.
struct Frame {
    Scene scene;
    std::vector<Bounds> bounds;
    std::vector<Ray> rays;
    FrameGeometry geometry;
    int width = 0, height = 0;

    Frame(Scene s, const Camera& camera, int w, int h) : scene(std::move(s)), width(w), height(h) {
        bounds = allTriangleBounds(scene.triangles);
        rays = primaryRays(camera, w, h);
        geometry = frameGeometry(scene.triangles, bounds, rays, sceneBounds(scene.triangles));
    }
    Frame(const Frame&) = delete;

    TraceResult trace(Backend backend, unsigned regions = 0, unsigned threads = 1,
                      DivisionAxis axis = DivisionAxis::Best) const {
        TraceOptions o;
        o.backend = backend;
        o.regions = regions;
        o.threads = threads;
        o.axis = axis;
        ThreadPool pool(threads);
        return traceCpu(geometry, o, pool);
    }
};

inline Camera defaultCamera(const Scene& scene, int w, int h, CameraOptions options = {}) {
    return makeCameras(scene, sceneBounds(scene.triangles), options, double(w) / double(h)).front();
}

// Primitive id and depth identical bit for bit; reports the first few differing pixels.
inline ::testing::AssertionResult identicalHits(const std::vector<Hit>& a, const std::vector<Hit>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
    std::size_t differing = 0;
    std::string examples;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i].prim == b[i].prim && std::memcmp(&a[i].t, &b[i].t, sizeof(float)) == 0) continue;
        if (++differing <= 5)
            examples += " [pixel " + std::to_string(i) + ": prim " + std::to_string(a[i].prim) + " t " +
                        std::to_string(a[i].t) + " vs prim " + std::to_string(b[i].prim) + " t " +
                        std::to_string(b[i].t) + "]";
    }
    if (differing == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << differing << " differing pixels:" << examples;
}

inline std::size_t hitCount(const std::vector<Hit>& hits) {
    std::size_t n = 0;
    for (const Hit& h : hits) n += h.prim != kMissPrim;
    return n;
}

}  // namespace dacrt::test
