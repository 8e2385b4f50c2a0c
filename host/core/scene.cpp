#include "core/scene.hpp"

#include <atomic>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"
#include "core/triangle_bounds_lanes.hpp"

namespace dacrt {

void touchTriangles(Scene& scene) {
    static std::atomic<std::uint64_t> next{1};
    scene.trianglesVersion = next++;
}

void applyCullMode(Scene& scene, CullMode mode) {
    touchTriangles(scene);
    for (std::size_t i = 0; i < scene.triangles.size(); ++i) {
        const bool materialCulls =
            i < scene.materialOfTriangle.size() && !scene.materials[scene.materialOfTriangle[i]].doubleSided;
        const bool cull = mode == CullMode::BackFaces || (mode == CullMode::Material && materialCulls);
        scene.triangles[i].cullBackFace = cull ? 1u : 0u;
    }
}

std::uint64_t singleSidedTriangles(const std::vector<Triangle>& triangles) {
    std::uint64_t n = 0;
    for (const Triangle& t : triangles) n += t.cullBackFace != 0u;
    return n;
}

Bounds triangleBounds(const Triangle& t) {
    Bounds b{};
    b.lo = glm::min(t.v0, glm::min(t.v1, t.v2));
    b.hi = glm::max(t.v0, glm::max(t.v1, t.v2));
    return b;
}

glm::vec3 geometricNormal(const Triangle& t) {
    const glm::dvec3 n = glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0));
    const double len = glm::length(n);
    return len > 0.0 ? glm::vec3(n / len) : glm::vec3(0.0f);
}

Box sceneBounds(const std::vector<Triangle>& triangles) {
    Box box;
    for (const Triangle& t : triangles) {
        box.extend(t.v0);
        box.extend(t.v1);
        box.extend(t.v2);
    }
    return box;
}

std::vector<Bounds> allTriangleBounds(const std::vector<Triangle>& triangles) {
    std::vector<Bounds> bounds(triangles.size());
    for (std::size_t i = 0; i < triangles.size(); ++i) bounds[i] = triangleBounds(triangles[i]);
    return bounds;
}

void triangleBoundsInParallel(const std::vector<Triangle>& triangles, ThreadPool& pool, std::vector<Bounds>& bounds,
                              Box& box, std::vector<float>* columns) {
    const std::size_t n = triangles.size();
    reserveMapped(bounds, n);
    bounds.resize(n);
    if (columns) resizeMapped(*columns, 6 * n);
    std::vector<Box> chunkBox((n + kFrameScanChunk - 1) / kFrameScanChunk);
    forEachChunk(n, kFrameScanChunk, &pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
        triangleBoundsLanes(triangles.data() + begin, end - begin, bounds.data() + begin, chunkBox[c]);
        if (!columns) return;
        // From the chunk's bounds while they are in the caches.
        float* column = columns->data();
        for (int axis = 0; axis < 3; ++axis)
            for (std::size_t i = begin; i < end; ++i) {
                column[std::size_t(axis) * n + i] = bounds[i].lo[axis];
                column[std::size_t(3 + axis) * n + i] = bounds[i].hi[axis];
            }
    });
    box = Box{};
    for (const Box& b : chunkBox) {
        box.lo = glm::min(box.lo, b.lo);
        box.hi = glm::max(box.hi, b.hi);
    }
}

namespace {

bool placeable(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) &&
           glm::all(glm::lessThanEqual(glm::abs(v), glm::vec3(kMaxCoordinate)));
}

// Refuses triangle i, naming its first vertex that is not finite or out of range, and where it came from.
[[noreturn]] void refuseTriangle(const Scene& scene, std::size_t i) {
    const Triangle& t = scene.triangles[i];
    const glm::vec3 v = !placeable(t.v0) ? t.v0 : !placeable(t.v1) ? t.v1 : t.v2;
    const bool finite = std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    std::ostringstream msg;
    msg << scene.name << ": " << (finite ? "out-of-range" : "non-finite") << " vertex position (" << v.x << ", " << v.y
        << ", " << v.z << ") in triangle " << i;
    if (i < scene.sources.size()) {
        const TriangleSource& s = scene.sources[i];
        msg << " (node " << s.node << ", mesh " << s.mesh << ", primitive " << s.primitive << ", triangle " << s.triangle << ")";
    }
    if (finite) msg << "; coordinates must lie within +-" << kMaxCoordinate << " so that every intersection intermediate stays finite";
    throw InputError(msg.str());
}

}  // namespace

void validateScene(const Scene& scene, ThreadPool* pool) {
    if (scene.triangles.empty())
        throw InputError(scene.name + ": the scene has no triangles" +
                         (scene.degenerateTrianglesDropped
                              ? " that can be hit (all " + std::to_string(scene.degenerateTrianglesDropped) +
                                    " have no area and were dropped)"
                              : std::string()));
    if (scene.triangles.size() >= kMissPrim)
        throw InputError(scene.name + ": too many triangles for 32-bit primitive ids");
    // In chunks on the pool; the first offending triangle of all is refused.
    const std::size_t n = scene.triangles.size();
    const std::size_t first = firstFailureInChunks(n, 65536, pool, [&](std::size_t i) {
        const Triangle& t = scene.triangles[i];
        return placeable(t.v0) && placeable(t.v1) && placeable(t.v2);
    });
    if (first < n) refuseTriangle(scene, first);
}

std::vector<std::pair<std::string, std::uint64_t>> sceneArrayBytes(const Scene& scene) {
    auto bytes = [](const auto& v) { return std::uint64_t(v.size()) * sizeof(v[0]); };
    std::uint64_t textures = 0;
    for (const Texture& t : scene.textures) textures += t.rgba.size();
    return {{"triangle sources", bytes(scene.sources)},
            {"triangle materials", bytes(scene.materialOfTriangle)},
            {"corner normals", bytes(scene.corners.normals)},
            {"corner texture coordinates", bytes(scene.corners.texCoords)},
            {"corner colours", bytes(scene.corners.colors)},
            {"textures", textures}};
}

}  // namespace dacrt
