#pragma once
// The flattened scene every backend consumes: one triangle array with provenance.
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <dacrt/scene_options.hpp>
#include <glm/glm.hpp>

#include "core/enum_names.hpp"
#include "core/shader_layout.hpp"
#include "core/thread_pool.hpp"

namespace dacrt {

// Largest accepted coordinate magnitude (vertices and camera). With |x| <= 1e9 every
// intermediate of the watertight test stays below 2^110, far from float overflow.
constexpr float kMaxCoordinate = 1e9f;

// How a texture's coordinates outside [0, 1] wrap (glTF sampler wrapS, wrapT).
enum class TextureWrap { Repeat, ClampToEdge, MirroredRepeat };

// A decoded image: 8-bit RGBA texels as the file stores them (base colour: sRGB), row 0 at the
// top (glTF's texture coordinate (0, 0) is the top-left corner).
struct Texture {
    std::string name;
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;
};

// A material's use of a texture: which one, through which coordinates and sampler.
struct TextureBinding {
    int texture = -1;              // index into Scene::textures; -1: none
    std::uint32_t texCoord = 0;    // TEXCOORD_n (after KHR_texture_transform's override)
    TextureWrap wrapS = TextureWrap::Repeat;
    TextureWrap wrapT = TextureWrap::Repeat;
    bool nearest = false;          // magnification NEAREST (no mipmaps are built: minification samples like it)
    glm::mat3 transform{1.0f};     // KHR_texture_transform: uv' = transform * (u, v, 1)
};

struct Material {
    std::string name;
    glm::vec4 baseColor{1.0f};
    bool doubleSided = false;  // glTF's default: single-sided, back faces culled
    TextureBinding baseColorTexture;
};

// Per-corner shading inputs of each triangle, in the triangle's corner order (after a
// mirroring node's corner swap). Each array is empty when no primitive of the scene has the
// attribute; otherwise it has one entry per triangle, with the defaults below where the
// triangle's primitive lacks it.
struct CornerAttributes {
    std::vector<std::array<glm::vec3, 3>> normals;    // world space, unit; (0, 0, 0): use the geometric normal
    std::vector<std::array<glm::vec2, 3>> texCoords;  // the set the triangle's base colour texture reads; (0, 0)
    std::vector<std::array<glm::vec4, 3>> colors;     // COLOR_0, linear RGBA; (1, 1, 1, 1)
};

// KHR_lights_punctual, placed in world space. Loaded for the secondary-ray passes.
enum class LightType { Point, Spot, Directional };
template <>
struct EnumNames<LightType> {
    static constexpr std::array<std::pair<LightType, std::string_view>, 3> table{
        {{LightType::Point, "point"}, {LightType::Spot, "spot"}, {LightType::Directional, "directional"}}};
};
struct Light {
    std::string name;
    LightType type = LightType::Point;
    glm::vec3 color{1.0f};
    float intensity = 1.0f;        // candela (point, spot) or lux (directional)
    float range = 0.0f;            // 0: infinite
    float innerConeAngle = 0.0f;   // spot only, radians
    float outerConeAngle = float(M_PI / 4.0);
    glm::dvec3 position{0.0};      // point, spot
    glm::dvec3 direction{0.0, 0.0, -1.0};  // spot, directional: where the light travels, unit
    std::uint32_t node = 0;
};

// CullMode (which back faces no ray hits) is defined in the public <dacrt/scene_options.hpp>;
// its names as the command line gives them:
template <>
struct EnumNames<CullMode> {
    static constexpr std::array<std::pair<CullMode, std::string_view>, 3> table{
        {{CullMode::Material, "material"}, {CullMode::None, "none"}, {CullMode::BackFaces, "backfaces"}}};
};

// What a glTF file holds beyond the flattened scene, one line per item, for `dacrt info`.
struct GltfInventory {
    std::vector<std::string> scenes;      // "0 'name': K root nodes" (the loaded one marked)
    std::vector<std::string> meshes;      // with primitives and triangles
    std::vector<std::string> materials;
    std::vector<std::string> textures;
    std::vector<std::string> skins;       // with joints and the nodes they deform
    std::vector<std::string> extensionsUsed;
    std::vector<std::string> extensionsRequired;
    std::uint32_t loadedScene = 0;
};

// Where a flattened triangle came from in the glTF file.
struct TriangleSource {
    std::uint32_t node = 0;
    std::uint32_t mesh = 0;
    std::uint32_t primitive = 0;
    std::uint32_t triangle = 0;   // index within the primitive
};

enum class Projection { Perspective, Orthographic };
template <>
struct EnumNames<Projection> {
    static constexpr std::array<std::pair<Projection, std::string_view>, 2> table{
        {{Projection::Perspective, "perspective"}, {Projection::Orthographic, "orthographic"}}};
};

struct SceneCamera {
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double yfovRadians = 0.0;                      // perspective
    Projection projection = Projection::Perspective;
    double ymag = 0.0;                             // orthographic: half the view's height
    std::string name;                              // the glTF camera's
    std::int32_t cameraIndex = -1;                 // in the file's cameras; -1: not from a file
    std::int32_t node = -1;                        // the node that places it
};

struct Scene {
    std::string name;
    std::vector<Triangle> triangles;
    std::vector<TriangleSource> sources;          // one per triangle
    std::vector<std::uint32_t> materialOfTriangle;  // index into materials
    std::vector<Material> materials;
    CornerAttributes corners;                       // normals, texture coordinates, vertex colours
    std::vector<Texture> textures;                  // the decoded images materials use
    std::vector<Light> lights;                      // KHR_lights_punctual, as placed by the scene's nodes
    std::vector<SceneCamera> cameras;               // every camera the scene's nodes place, in node order
    std::optional<SceneCamera> camera;              // the one frames are rendered from: the first placed, or the one chosen
    GltfInventory inventory;                        // what the file holds (dacrt info)
    std::uint64_t degenerateTrianglesDropped = 0;   // no area (triangleHasNoArea), dropped at load
    std::vector<std::string> warnings;              // what the loader ignored, one line each (render prints them)
    // What each stage of its set-up took (ms), in order: the flattening's phases and the
    // checks (GltfDocument::scene), then the caller's (dacrt render: the cull mode).
    std::vector<std::pair<std::string, double>> setupPhasesMs;
    // Changes whenever `triangles` does (load, applyCullMode): a frame's FrameGeometry
    // trianglesVersion, unique in the process. Code that edits `triangles` itself calls
    // touchTriangles(*this).
    std::uint64_t trianglesVersion = 0;

    std::size_t triangleCount() const { return triangles.size(); }
};

// The bytes of the scene's per-triangle arrays that no tracer's memory plan counts (the plans
// count the triangles themselves): provenance, materials, corner attributes, and the decoded
// textures; by name, as render --stats reports them beside the plan.
std::vector<std::pair<std::string, std::uint64_t>> sceneArrayBytes(const Scene& scene);

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
// columns (where given): the same bounds' coordinates in six columns of triangles.size()
// floats each, the low faces' x, y and z, then the high faces' (column (side * 3 + axis) holds
// triangle i's at i), resized the same way: what the cpu triangle filters read (simd::TriangleFaces).
void triangleBoundsInParallel(const std::vector<Triangle>& triangles, ThreadPool& pool, std::vector<Bounds>& bounds,
                              Box& box, std::vector<float>* columns = nullptr);

// Checks that the scene can be traced: triangles exist and every coordinate is finite.
// Throws InputError naming the first offending triangle and its provenance. On pool's threads
// where given (the same triangle is named).
void validateScene(const Scene& scene, ThreadPool* pool = nullptr);

}  // namespace dacrt
