#pragma once
// Frames built from scenes for the tracer tests, and hit comparison.
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "core/scene.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/secondary_rays.hpp"
#include "support/fixtures.hpp"

namespace dacrt::test {

// One frame on one of the CPU backends.
inline TraceResult traceFrame(const FrameGeometry& geometry, Backend backend, unsigned regions = 0, unsigned threads = 1,
                              DivisionAxis axis = DivisionAxis::Best, const DacrtOptions& dacrt = {}) {
    TraceOptions o;
    o.dacrt = dacrt;
    o.backend = backend;
    o.regions = regions;
    o.threads = threads;
    o.axis = axis;
    ThreadPool pool(threads);
    return traceCpu(geometry, o, pool);
}

// A scene, its bounds and one camera's rays: everything a tracer reads.
struct Frame {
    Scene scene;
    std::vector<Bounds> bounds;
    std::vector<Ray> rays;
    FrameGeometry geometry;
    int width = 0, height = 0;

    Frame(Scene s, const Camera& camera, int w, int h) : scene(std::move(s)), width(w), height(h) { prepare(camera); }
    // The scene's own default camera with `options` applied, made after the scene is moved in.
    Frame(Scene s, int w, int h, const CameraOptions& options) : scene(std::move(s)), width(w), height(h) {
        prepare(makeCameras(scene, sceneBounds(scene.triangles), options, double(w) / double(h)).front());
    }
    Frame(const Frame&) = delete;

    TraceResult trace(Backend backend, unsigned regions = 0, unsigned threads = 1,
                      DivisionAxis axis = DivisionAxis::Best, const DacrtOptions& dacrt = {}) const {
        return traceFrame(geometry, backend, regions, threads, axis, dacrt);
    }

private:
    void prepare(const Camera& camera) {
        bounds = allTriangleBounds(scene.triangles);
        rays = primaryRays(camera, width, height);
        geometry = frameGeometry(scene.triangles, bounds, rays, sceneBounds(scene.triangles), std::uint32_t(width));
    }
};

// A secondary pass of a frame, made on the host from the primary hits: its rays and the frame
// they are traced as (any hit, or the closest when `query` asks for it).
struct PassFrame {
    SecondaryRays rays;
    FrameGeometry geometry;
    PassFrame(const Frame& primary, const std::vector<Hit>& primaryHits, const SecondaryPass& pass,
              HitQuery query = HitQuery::Any) {
        ThreadPool pool(2);
        rays = makeSecondaryRays(pass, primary.rays, primaryHits, primary.scene.triangles, pool);
        geometry = secondaryFrame(primary.scene.triangles, primary.bounds, rays.rays, sceneBounds(primary.scene.triangles));
        geometry.query = query;
    }
    PassFrame(const PassFrame&) = delete;
    TraceResult trace(Backend backend, unsigned regions = 0, unsigned threads = 1,
                      DivisionAxis axis = DivisionAxis::Best, const DacrtOptions& dacrt = {}) const {
        return traceFrame(geometry, backend, regions, threads, axis, dacrt);
    }
};

// An occlusion pass of `samples` rays per hit, `length` long.
inline SecondaryPass occlusionPass(std::uint32_t samples, float length, std::uint32_t seed = 7) {
    SecondaryPass p;
    p.name = "occlusion";
    p.kind = shared::kPassOcclusion;
    p.raysPerHit = samples;
    p.occlusionDistance = length;
    p.sampleSeed = seed;
    return p;
}

// A shadow pass towards a point light at `position`.
inline SecondaryPass pointShadowPass(glm::vec3 position) {
    SecondaryPass p;
    p.name = "shadow";
    p.kind = shared::kPassShadow;
    p.light.type = shared::kLightPoint;
    p.light.position = position;
    return p;
}

// A frame's primary hits (brute force's) and secondary passes made from them: the inputs on
// which the peer backends (Embree, ray queries) are compared with brute force on rays that
// leave surfaces.
struct SecondaryPassSet {
    std::string name;
    Frame frame;
    TraceResult primary;
    std::vector<std::pair<std::string, SecondaryPass>> passes;

    SecondaryPassSet(std::string setName, Scene scene, const CameraOptions& camera,
                     std::vector<std::pair<std::string, SecondaryPass>> setPasses, int width = 48, int height = 36)
        : name(std::move(setName)), frame(std::move(scene), width, height, camera), primary(frame.trace(Backend::Brute, 0, 2)),
          passes(std::move(setPasses)) {}
    SecondaryPassSet(const SecondaryPassSet&) = delete;
};

// The shapes from a raised camera (test_secondary_rays.cpp's view): ambient occlusion rays
// 0.8 long (shorter than most gaps between the shapes, so the segment's end decides many
// rays) and unbounded, and shadow rays towards a point light above the shapes and one among
// them.
inline SecondaryPassSet shapesSecondaryPasses() {
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 1.5, 4.0);
    return SecondaryPassSet("shapes", shapesScene(), camera,
                            {{"occlusion 0.8", occlusionPass(4, 0.8f)},
                             {"occlusion unbounded", occlusionPass(4, kNoHitT)},
                             {"shadow, light above", pointShadowPass({0.3f, 1.6f, 0.4f})},
                             {"shadow, light among the shapes", pointShadowPass({0.0f, -0.2f, 0.0f})}});
}

// The shapes under a single-sided ceiling whose front faces up, seen from below it, with a
// point light above it: every shadow ray crosses the ceiling from behind (every surface lies
// below the ceiling and within its extent, so the segment from a lit point to the light meets
// it), and so do the upward occlusion rays. Without the face rule no shadow ray would be clear.
inline SecondaryPassSet shapesUnderACeilingPasses() {
    std::vector<Mesh> meshes = shapesMeshes();
    meshes.push_back(grid({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 4, 4));
    CameraOptions camera;
    camera.eye = glm::dvec3(0.5, 0.6, 4.0);
    return SecondaryPassSet("shapes under a ceiling", sceneFromMeshes(meshes, "shapes under a ceiling"), camera,
                            {{"occlusion unbounded", occlusionPass(4, kNoHitT)},
                             {"shadow, light above the ceiling", pointShadowPass({0.3f, 2.0f, 0.4f})}});
}

// A shadow pass towards a directional light shining along `direction`.
inline SecondaryPass directionalShadowPass(glm::dvec3 direction) {
    SecondaryPass p = pointShadowPass({});
    p.light.type = shared::kLightDirectional;
    p.light.direction = glm::vec3(glm::normalize(direction));
    return p;
}

// The same visibility (hit or not) ray by ray; reports the first few differing rays.
inline ::testing::AssertionResult identicalVisibility(const std::vector<Hit>& a, const std::vector<Hit>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes " << a.size() << " and " << b.size();
    std::size_t differing = 0;
    std::string examples;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if ((a[i].prim == kMissPrim) == (b[i].prim == kMissPrim)) continue;
        if (++differing <= 5)
            examples += " [ray " + std::to_string(i) + ": prim " + std::to_string(a[i].prim) + " vs " + std::to_string(b[i].prim) + "]";
    }
    if (differing == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << differing << " rays differ in visibility:" << examples;
}

// An orthographic camera at `eye` looking at the origin, 2 ymag high, y up.
inline Camera orthographicView(glm::dvec3 eye, double ymag) {
    Camera c;
    c.eye = eye;
    c.forward = glm::normalize(-eye);
    const glm::dvec3 right = glm::normalize(glm::cross(c.forward, glm::dvec3(0, 1, 0)));
    c.up = glm::cross(right, c.forward);
    c.projection = Projection::Orthographic;
    c.ymag = ymag;
    return c;
}

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
