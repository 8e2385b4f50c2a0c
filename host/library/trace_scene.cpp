// The public TraceScene: a glTF file's scene as `dacrt render` loads it, or triangles from the
// caller's arrays, checked with messages that name the caller's element.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>

#include <dacrt/errors.hpp>
#include <dacrt/results.hpp>

#include "core/gltf_loader.hpp"
#include "core/system_memory.hpp"
#include "core/triangle_rules.hpp"
#include "library/api_state.hpp"

namespace dacrt {

namespace {

const char* const kAxisNames[3] = {"x", "y", "z"};

void checkArraySizes(std::size_t positions, std::size_t indices, std::size_t flags) {
    if (positions % 3 != 0)
        throw InputError("positions: " + std::to_string(positions) +
                         " floats are not whole vertices (three floats, x, y and z, per vertex)");
    if (indices % 3 != 0)
        throw InputError("indices: " + std::to_string(indices) +
                         " indices are not whole triangles (three vertex indices per triangle)");
    if (indices / 3 >= std::uint64_t(kUnnamedPrimitive))
        throw InputError("indices: too many triangles for 32-bit primitive ids");
    if (flags != 0 && flags != indices / 3)
        throw InputError("singleSided: " + std::to_string(flags) + " flags for " + std::to_string(indices / 3) +
                         " triangles (one per triangle, or none: every triangle two-sided)");
}

void checkPositions(std::span<const float> positions) {
    for (std::size_t k = 0; k < positions.size(); ++k) {
        const float c = positions[k];
        if (std::isfinite(c) && std::abs(c) <= kMaxCoordinate) continue;
        std::ostringstream msg;
        msg << "positions[" << k << "] (vertex " << k / 3 << ", " << kAxisNames[k % 3] << ") is " << c;
        if (std::isfinite(c)) msg << ": coordinates must lie within +-" << kMaxCoordinate
                                  << " so that every intersection intermediate stays finite";
        else msg << ": coordinates must be finite";
        throw InputError(msg.str());
    }
}

void checkIndices(std::span<const std::uint32_t> indices, std::size_t vertices) {
    for (std::size_t k = 0; k < indices.size(); ++k)
        if (indices[k] >= vertices)
            throw InputError("indices[" + std::to_string(k) + "] (triangle " + std::to_string(k / 3) + ") is " +
                             std::to_string(indices[k]) + ", but positions hold " + std::to_string(vertices) +
                             " vertices");
}

glm::vec3 vertex(std::span<const float> positions, std::uint32_t index) {
    return {positions[3 * std::size_t(index)], positions[3 * std::size_t(index) + 1],
            positions[3 * std::size_t(index) + 2]};
}

// Triangle k of the caller's arrays placed at `positions` (its face rule kept).
void placeTriangle(Triangle& t, std::span<const float> positions, std::span<const std::uint32_t> indices,
                   std::size_t k) {
    t.v0 = vertex(positions, indices[3 * k]);
    t.v1 = vertex(positions, indices[3 * k + 1]);
    t.v2 = vertex(positions, indices[3 * k + 2]);
}

// setPositions keeps the triangles traced: one that fromArrays dropped for having no area must
// still have none.
void checkDroppedStayDropped(std::span<const float> positions, const TraceScene::Impl& s) {
    if (s.callerIds.empty()) return;  // none was dropped
    std::size_t traced = 0;
    for (std::uint32_t k = 0; k < s.indices.size() / 3; ++k) {
        if (traced < s.callerIds.size() && s.callerIds[traced] == k) {
            ++traced;
            continue;
        }
        Triangle t{};
        placeTriangle(t, positions, s.indices, k);
        if (!shared::triangleHasNoArea(t.v0, t.v1, t.v2))
            throw InputError("positions: triangle " + std::to_string(k) + " had no area when the scene was made, so it "
                             "is not traced, and has area now: setPositions keeps the triangles a scene traces; make "
                             "the scene anew with fromArrays");
    }
}

}  // namespace

std::uint64_t TraceScene::Impl::newId() {
    static std::atomic<std::uint64_t> next{1};
    return next++;
}

TraceScene::TraceScene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TraceScene::TraceScene(TraceScene&&) noexcept = default;
TraceScene& TraceScene::operator=(TraceScene&&) noexcept = default;
TraceScene::~TraceScene() = default;

TraceScene TraceScene::load(const std::string& path, const SceneLoadOptions& options) {
    Scene scene = loadGltf(path, {}, GltfSelection{.scene = options.scene, .animation = options.animation, .time = options.time});
    selectCamera(scene, options.camera);
    applyCullMode(scene, options.cull);
    return TraceScene(std::make_unique<Impl>(std::move(scene)));
}

TraceScene TraceScene::fromArrays(std::span<const float> positions, std::span<const std::uint32_t> indices,
                                  std::span<const std::uint8_t> singleSided) {
    checkArraySizes(positions.size(), indices.size(), singleSided.size());
    // What the scene keeps of each triangle: its vertices, bounds, source and caller's id.
    checkFitsInMemory("a scene of " + std::to_string(indices.size() / 3) + " triangles",
                      std::uint64_t(indices.size() / 3) *
                          (sizeof(Triangle) + sizeof(Bounds) + sizeof(TriangleSource) + sizeof(std::uint32_t)),
                      "trace fewer triangles");
    checkPositions(positions);
    checkIndices(indices, positions.size() / 3);
    Scene scene;
    scene.name = "scene from arrays";
    std::vector<std::uint32_t> callerIds;
    for (std::uint32_t k = 0; k < indices.size() / 3; ++k) {
        Triangle t{};
        placeTriangle(t, positions, indices, k);
        t.cullBackFace = !singleSided.empty() && singleSided[k] != 0 ? 1u : 0u;
        // The loader's rule: no ray can hit a triangle with no area (docs/gltf-input.md).
        if (shared::triangleHasNoArea(t.v0, t.v1, t.v2)) {
            ++scene.degenerateTrianglesDropped;
            continue;
        }
        scene.triangles.push_back(t);
        scene.sources.push_back(TriangleSource{.triangle = k});
        callerIds.push_back(k);
    }
    validateScene(scene);
    touchTriangles(scene);
    auto impl = std::make_unique<Impl>(std::move(scene));
    if (impl->scene.degenerateTrianglesDropped != 0) impl->callerIds = std::move(callerIds);
    impl->indices.assign(indices.begin(), indices.end());
    impl->vertices = positions.size() / 3;
    return TraceScene(std::move(impl));
}

void TraceScene::setPositions(std::span<const float> positions) {
    Impl& s = *impl_;
    if (s.indices.empty())
        throw InputError("setPositions moves the vertices of a scene made by fromArrays; this one was loaded from a "
                         "file: load it again at the new instant (SceneLoadOptions::time)");
    if (positions.size() != 3 * s.vertices)
        throw InputError("positions: " + std::to_string(positions.size()) + " floats, but the scene has " +
                         std::to_string(s.vertices) + " vertices (three floats each): setPositions moves them; "
                         "fromArrays makes a scene with another count");
    checkPositions(positions);
    checkDroppedStayDropped(positions, s);
    // In place: the peers' structures read this array where it is (tracer.hpp).
    for (std::size_t i = 0; i < s.scene.triangles.size(); ++i)
        placeTriangle(s.scene.triangles[i], positions, s.indices, s.callerIds.empty() ? i : s.callerIds[i]);
    touchTriangles(s.scene);
    s.box = sceneBounds(s.scene.triangles);
}

std::size_t TraceScene::triangleCount() const { return impl_->scene.triangles.size(); }

std::uint64_t TraceScene::trianglesDropped() const { return impl_->scene.degenerateTrianglesDropped; }

namespace {

// The traced triangle a hit's primitive id names (callerIds: fromArrays's numbering, sorted).
const Triangle& triangleNamed(const TraceScene::Impl& s, std::uint32_t id) {
    std::size_t index = id;
    if (!s.callerIds.empty()) {
        const auto at = std::lower_bound(s.callerIds.begin(), s.callerIds.end(), id);
        index = at != s.callerIds.end() && *at == id ? std::size_t(at - s.callerIds.begin()) : s.scene.triangles.size();
    }
    if (index >= s.scene.triangles.size())
        throw InputError("primitive id " + std::to_string(id) + " names no triangle of the scene (" +
                         std::to_string(s.scene.triangles.size()) + " traced" +
                         (s.callerIds.empty() ? std::string() : ", numbered as given, those with no area dropped") + ")");
    return s.scene.triangles[index];
}

}  // namespace

void TraceScene::geometricNormals(std::span<const std::uint32_t> primitives, std::span<float> normals) const {
    if (normals.size() != 3 * primitives.size())
        throw InputError("geometricNormals: " + std::to_string(normals.size()) + " floats for " +
                         std::to_string(primitives.size()) + " primitive ids (three per id)");
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        const std::uint32_t id = primitives[i];
        const glm::vec3 n = id == kNoPrimitive || id == kUnnamedPrimitive ? glm::vec3(0.0f)
                                                                          : geometricNormal(triangleNamed(*impl_, id));
        normals[3 * i] = n.x;
        normals[3 * i + 1] = n.y;
        normals[3 * i + 2] = n.z;
    }
}

SceneBounds TraceScene::bounds() const {
    const Box& box = impl_->box;
    return SceneBounds{{box.lo.x, box.lo.y, box.lo.z}, {box.hi.x, box.hi.y, box.hi.z}};
}

}  // namespace dacrt
