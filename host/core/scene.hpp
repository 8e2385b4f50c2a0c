#pragma once
// The flattened scene every backend consumes: one triangle array with provenance.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/enum_names.hpp"
#include "core/shader_layout.hpp"
#include "core/thread_pool.hpp"

namespace dacrt {

// Largest accepted coordinate magnitude (vertices and camera). With |x| <= 1e9 every
// intermediate of the watertight test stays below 2^110, far from float overflow.
constexpr float kMaxCoordinate = 1e9f;

struct Material {
    glm::vec4 baseColor{1.0f};
    bool doubleSided = false;  // glTF's default: single-sided, back faces culled
};

// Which back faces no ray hits (Triangle::cullBackFace): the materials' (glTF's rule, the
// default), none, or every triangle's.
enum class CullMode { Material, None, BackFaces };
template <>
struct EnumNames<CullMode> {
    static constexpr std::array<std::pair<CullMode, std::string_view>, 3> table{
        {{CullMode::Material, "material"}, {CullMode::None, "none"}, {CullMode::BackFaces, "backfaces"}}};
};

// Where a flattened triangle came from in the glTF file.
struct TriangleSource {
    std::uint32_t node = 0;
    std::uint32_t mesh = 0;
    std::uint32_t primitive = 0;
    std::uint32_t triangle = 0;   // index within the primitive
};

struct SceneCamera {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double yfovRadians = 0.0;
};

struct Scene {
    std::string name;
    std::vector<Triangle> triangles;
    std::vector<TriangleSource> sources;          // one per triangle
    std::vector<std::uint32_t> materialOfTriangle;  // index into materials
    std::vector<Material> materials;
    std::optional<SceneCamera> camera;              // the first perspective camera found
    std::uint64_t degenerateTrianglesDropped = 0;   // no area (triangleHasNoArea), dropped at load
    std::vector<std::string> warnings;              // what the loader ignored, one line each (render prints them)
    // Changes whenever `triangles` does (load, applyCullMode): a frame's FrameGeometry
    // trianglesVersion, unique in the process. Code that edits `triangles` itself calls
    // touchTriangles(*this).
    std::uint64_t trianglesVersion = 0;

    std::size_t triangleCount() const { return triangles.size(); }
};

struct Box {
    glm::vec3 lo{kNoHitT};
    glm::vec3 hi{-kNoHitT};
    void extend(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    glm::vec3 center() const { return (lo + hi) * 0.5f; }
    glm::vec3 extent() const { return hi - lo; }
};

// A new trianglesVersion, unique in the process, for a scene whose triangles changed.
void touchTriangles(Scene& scene);

// Sets every triangle's cullBackFace under `mode` (from its material under CullMode::Material).
void applyCullMode(Scene& scene, CullMode mode);
std::uint64_t singleSidedTriangles(const std::vector<Triangle>& triangles);

Bounds triangleBounds(const Triangle& t);
// Unit normal of the triangle's plane (winding order), in double before rounding; 0 when it
// has no area.
glm::vec3 geometricNormal(const Triangle& t);
Box sceneBounds(const std::vector<Triangle>& triangles);
std::vector<Bounds> allTriangleBounds(const std::vector<Triangle>& triangles);
// Both at once on every thread of pool, into bounds (resized; reusing its memory from frame to
// frame) and box: the same values as allTriangleBounds and sceneBounds, bit for bit (chunks
// are merged in order, so even the sign of a zero bound is the sequential one).
void triangleBoundsInParallel(const std::vector<Triangle>& triangles, ThreadPool& pool, std::vector<Bounds>& bounds,
                              Box& box);

// Checks that the scene can be traced: triangles exist and every coordinate is finite.
// Throws InputError naming the first offending triangle and its provenance.
void validateScene(const Scene& scene);

}  // namespace dacrt
