#pragma once
// A scene to trace: triangles loaded from a glTF file or given as arrays, each with its face
// rule, checked once; the vertices of arrays can move from frame to frame (setPositions).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <dacrt/scene_options.hpp>

namespace dacrt {

class RayBatch;
class Tracer;

struct SceneBounds {
    std::array<float, 3> lo{};
    std::array<float, 3> hi{};
};

class TraceScene {
public:
    // The file's scene (.gltf or .glb) flattened into world-space triangles at the options'
    // instant, with the face rule of `options.cull`. A triangle's primitive id in the hits is
    // its index in that flattening (nodes, meshes, primitives in file order). Throws
    // InputError naming the file and the problem.
    static TraceScene load(const std::string& path, const SceneLoadOptions& options = {});

    // Triangles from arrays: `positions` holds x, y, z per vertex, `indices` three vertex
    // indices per triangle, `singleSided` (empty, or one per triangle) nonzero where a ray
    // that meets the triangle's back face does not hit it; empty: every triangle two-sided.
    // Triangles with no area are dropped (no ray can hit them); the hits keep the caller's
    // numbering (triangle k of `indices` is primitive k). Throws InputError on sizes that do
    // not match, an index out of range, a coordinate not finite or beyond +-1e9, no triangle
    // that can be hit, or more triangles than this machine's memory holds.
    static TraceScene fromArrays(std::span<const float> positions, std::span<const std::uint32_t> indices,
                                 std::span<const std::uint8_t> singleSided = {});

    // Moves the vertices of a scene made by fromArrays, for the next frame of an animation:
    // `positions` as fromArrays takes them, as many vertices; the indices and face rules stay,
    // and so do the triangles traced (their ids too). A triangle that has no area now is still
    // traced and never hit: every dacrt backend's intersection test rejects a triangle with no
    // area (Embree's and the ray queries' tests are their own). The triangles stay where they
    // are in memory, so a Tracer's next trace follows them as a dynamic scene's frame: the gpu
    // uploads them again, a peer rebuilds or refits its structure (tracer.hpp). Throws
    // InputError, changing nothing, on another vertex count, a coordinate fromArrays refuses, a
    // triangle fromArrays dropped (no area) that has area now, and for a scene loaded from a file
    // (load it again at the new instant: SceneLoadOptions::time).
    void setPositions(std::span<const float> positions);

    TraceScene(TraceScene&&) noexcept;
    TraceScene& operator=(TraceScene&&) noexcept;
    ~TraceScene();

    std::size_t triangleCount() const;          // triangles traced (those with area)
    std::uint64_t trianglesDropped() const;     // triangles with no area, dropped
    SceneBounds bounds() const;                 // of the traced triangles, exact

    // The unit geometric normal of each primitive id as the hits report it (the caller's
    // numbering), three floats each into `normals` (3 * primitives.size()): cross(v1 - v0,
    // v2 - v0) normalized, in double precision, as `dacrt render --aov` writes N; (0, 0, 0)
    // for kNoPrimitive and kUnnamedPrimitive. Throws InputError on another size, or an id that
    // names no traced triangle (out of range, or dropped for having no area).
    void geometricNormals(std::span<const std::uint32_t> primitives, std::span<float> normals) const;

    struct Impl;  // the library's own

private:
    explicit TraceScene(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
    friend class RayBatch;
    friend class Tracer;
};

}  // namespace dacrt
