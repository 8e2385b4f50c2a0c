#include "core/gltf_loader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>

#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/errors.hpp"
#include "core/json_nesting.hpp"
#include "core/system_memory.hpp"
#include "core/triangle_rules.hpp"

namespace dacrt {
namespace {

// What one flattened triangle costs while the scene is built and traced: the triangle, its
// provenance and material (Scene), and its bounds (allTriangleBounds).
constexpr std::uint64_t kBytesPerTriangle = sizeof(Triangle) + sizeof(TriangleSource) + 4 + sizeof(Bounds);
// Primitive ids are 32-bit and kMissPrim is reserved.
constexpr std::uint64_t kMaxTriangles = std::numeric_limits<std::uint32_t>::max() - 1;

std::string str(std::uint64_t v) { return std::to_string(v); }

// ---- before parsing ---------------------------------------------------------------------

bool isBinaryGltf(std::span<const unsigned char> bytes) {
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

std::uint32_t readU32(std::span<const unsigned char> bytes, std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;  // glTF is little-endian, as every machine dacrt runs on
}

// The JSON text: the whole file, or a .glb's first chunk when its header is consistent (an
// inconsistent header is left to the parser, which refuses it).
std::string_view jsonTextOf(std::span<const unsigned char> bytes) {
    const auto* chars = reinterpret_cast<const char*>(bytes.data());
    if (!isBinaryGltf(bytes)) return {chars, bytes.size()};
    if (bytes.size() < 20) return {};
    const std::uint64_t chunkLength = readU32(bytes, 12);
    if (20 + chunkLength > bytes.size()) return {};
    return {chars + 20, std::size_t(chunkLength)};
}

void checkJsonNesting(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits) {
    const JsonNesting n = jsonNesting(jsonTextOf(bytes), limits.maxJsonNesting);
    if (n.depth > limits.maxJsonNesting)
        throw InputError(name + ": the JSON nests objects and arrays more than " + str(limits.maxJsonNesting) +
                         " levels deep (at byte " + str(n.offset) + "); no glTF needs that many");
}

// ---- parsing ----------------------------------------------------------------------------

// Memory input never reads files: an external buffer is reported as missing.
bool noFileExists(const std::string&, void*) { return false; }
std::string keepPath(const std::string& path, void*) { return path; }
bool noFileRead(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
    if (err) *err += "external file '" + path + "' is not read from memory input\n";
    return false;
}

// Textures are not applied yet, so images stay undecoded: a file that carries them (most
// real-world .glb files) loads, and the flattener says they are ignored. tinygltf otherwise
// refuses every embedded or data-URI image ("No LoadImageData callback specified").
bool keepImageUndecoded(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                        void*) {
    return true;
}

tinygltf::Model parseGltf(std::span<const unsigned char> bytes, const std::string& name, const std::string& baseDir,
                          bool readFiles) {
    if (bytes.size() > std::numeric_limits<unsigned int>::max())
        throw InputError(name + ": " + str(bytes.size()) + " bytes is more than the glTF parser takes (4 GiB)");
    tinygltf::TinyGLTF reader;
    reader.SetStoreOriginalJSONForExtrasAndExtensions(false);
    reader.SetImageLoader(keepImageUndecoded, nullptr);
    if (!readFiles) reader.SetFsCallbacks(tinygltf::FsCallbacks{noFileExists, keepPath, noFileRead, nullptr, nullptr});
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = isBinaryGltf(bytes)
                 ? reader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir)
                 : reader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                              unsigned(bytes.size()), baseDir);
    } catch (const std::exception& e) {  // nlohmann::json throws on some malformed input
        throw InputError(name + ": not a valid glTF file (" + e.what() + ")");
    }
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        throw InputError(name + ": not a valid glTF file: " + (err.empty() ? std::string("unknown error") : err));
    }
    return model;
}

// ---- the rules of the glTF 2.0 specification the flattening relies on -------------------

// A view of one accessor's elements, every offset checked in 64-bit arithmetic that cannot
// wrap before any byte is read.
struct ElementView {
    const unsigned char* data = nullptr;
    std::uint64_t stride = 0;
    std::uint64_t count = 0;
    int componentType = 0;
};

class GltfChecker {
public:
    GltfChecker(const std::string& name, const tinygltf::Model& model) : name_(name), model_(model) {}

    [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

    // Sum and product that name the quantity instead of wrapping.
    std::uint64_t add(std::uint64_t a, std::uint64_t b, const std::string& what) const {
        std::uint64_t r;
        if (__builtin_add_overflow(a, b, &r)) fail(what + " overflows 64 bits (" + str(a) + " + " + str(b) + ")");
        return r;
    }
    std::uint64_t mul(std::uint64_t a, std::uint64_t b, const std::string& what) const {
        std::uint64_t r;
        if (__builtin_mul_overflow(a, b, &r)) fail(what + " overflows 64 bits (" + str(a) + " x " + str(b) + ")");
        return r;
    }

    void checkExtensions() const {
        // No extension changes how dacrt reads geometry yet: a file that requires one cannot be
        // read correctly without it.
        if (!model_.extensionsRequired.empty()) {
            std::string names;
            for (const std::string& e : model_.extensionsRequired) names += (names.empty() ? "" : ", ") + e;
            fail("the file requires the extension(s) " + names + ", which dacrt does not support");
        }
    }

    void checkCameras() const {
        for (std::size_t i = 0; i < model_.cameras.size(); ++i) {
            const tinygltf::Camera& c = model_.cameras[i];
            const std::string where = "camera " + str(i);
            if (c.type == "perspective") {
                const tinygltf::PerspectiveCamera& p = c.perspective;
                if (!(p.yfov > 0.0 && p.yfov < M_PI)) fail(where + ": yfov " + std::to_string(p.yfov) + " is not in (0, pi)");
                if (!(p.znear > 0.0) || !std::isfinite(p.znear)) fail(where + ": znear " + std::to_string(p.znear) + " must be > 0");
                // tinygltf reads an absent zfar (an infinite projection) or aspectRatio as 0.
                if (p.zfar != 0.0 && !(p.zfar > p.znear))
                    fail(where + ": zfar " + std::to_string(p.zfar) + " must be greater than znear " + std::to_string(p.znear));
                if (!(p.aspectRatio >= 0.0) || !std::isfinite(p.aspectRatio))
                    fail(where + ": aspectRatio " + std::to_string(p.aspectRatio) + " must be > 0");
            } else if (c.type == "orthographic") {
                const tinygltf::OrthographicCamera& o = c.orthographic;
                if (o.xmag == 0.0 || o.ymag == 0.0 || !std::isfinite(o.xmag) || !std::isfinite(o.ymag))
                    fail(where + ": xmag and ymag must be finite and not zero");
                if (!(o.znear >= 0.0) || !(o.zfar > o.znear) || !std::isfinite(o.zfar))
                    fail(where + ": an orthographic camera needs 0 <= znear < zfar");
            } else {
                fail(where + ": type '" + c.type + "' is neither perspective nor orthographic");
            }
        }
    }

    // Indices in range, at most one parent per node, roots without parents, no loops, finite
    // transforms of the right sizes, unit rotations. Returns each node's parent (-1 for none).
    // (A node with both a matrix and TRS cannot be told apart here: tinygltf reads the matrix
    // and skips TRS, which is the transform dacrt then uses.)
    std::vector<int> checkNodes() const {
        const std::size_t n = model_.nodes.size();
        std::vector<int> parent(n, -1);
        for (std::size_t i = 0; i < n; ++i) {
            const tinygltf::Node& node = model_.nodes[i];
            const std::string where = "node " + str(i);
            if (node.mesh >= 0 && std::size_t(node.mesh) >= model_.meshes.size())
                fail(where + " names mesh " + str(std::uint64_t(node.mesh)) + ", which does not exist");
            if (node.camera >= 0 && std::size_t(node.camera) >= model_.cameras.size())
                fail(where + " names camera " + str(std::uint64_t(node.camera)) + ", which does not exist");
            if (node.mesh < -1 || node.camera < -1) fail(where + " has a negative mesh or camera index");
            for (int child : node.children) {
                if (child < 0 || std::size_t(child) >= n) fail(where + " names child " + std::to_string(child) + ", which does not exist");
                if (parent[std::size_t(child)] >= 0)
                    fail("node " + std::to_string(child) + " is a child of both node " +
                         std::to_string(parent[std::size_t(child)]) + " and node " + str(i) +
                         " (glTF nodes form disjoint trees: one parent each)");
                parent[std::size_t(child)] = int(i);
            }
            auto finiteOfSize = [&](const std::vector<double>& v, std::size_t size, const char* what) {
                if (!v.empty() && v.size() != size) fail(where + ": " + what + " has " + str(v.size()) + " numbers, not " + str(size));
                for (double x : v)
                    if (!std::isfinite(x)) fail(where + ": " + what + " has a non-finite number");
            };
            finiteOfSize(node.matrix, 16, "matrix");
            finiteOfSize(node.translation, 3, "translation");
            finiteOfSize(node.rotation, 4, "rotation");
            finiteOfSize(node.scale, 3, "scale");
            if (node.rotation.size() == 4) {
                const double len = std::sqrt(node.rotation[0] * node.rotation[0] + node.rotation[1] * node.rotation[1] +
                                             node.rotation[2] * node.rotation[2] + node.rotation[3] * node.rotation[3]);
                if (!(std::abs(len - 1.0) <= 1e-5))
                    fail(where + ": the rotation quaternion has length " + std::to_string(len) + ", not 1");
            }
        }
        // With one parent each, a node on a loop is never reached from a parentless node.
        std::vector<char> reached(n, 0);
        std::vector<std::size_t> stack;
        for (std::size_t i = 0; i < n; ++i)
            if (parent[i] < 0) stack.push_back(i);
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            reached[i] = 1;
            for (int child : model_.nodes[i].children) stack.push_back(std::size_t(child));
        }
        for (std::size_t i = 0; i < n; ++i)
            if (!reached[i]) fail("node " + str(i) + " is part of a loop in the node hierarchy");
        return parent;
    }

    // The roots of the default scene (or, with no scene, every parentless node).
    std::vector<int> sceneRoots(const std::vector<int>& parent) const {
        std::vector<int> roots;
        if (model_.scenes.empty()) {
            for (std::size_t i = 0; i < parent.size(); ++i)
                if (parent[i] < 0) roots.push_back(int(i));
            return roots;
        }
        const int index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
        if (index >= int(model_.scenes.size())) fail("default scene " + std::to_string(index) + " does not exist");
        for (int root : model_.scenes[std::size_t(index)].nodes) {
            if (root < 0 || std::size_t(root) >= parent.size()) fail("scene " + std::to_string(index) + " names node " + std::to_string(root) + ", which does not exist");
            if (parent[std::size_t(root)] >= 0)
                fail("node " + std::to_string(root) + " is a root of scene " + std::to_string(index) + " but a child of node " +
                     std::to_string(parent[std::size_t(root)]));
            if (std::find(roots.begin(), roots.end(), root) != roots.end())
                fail("scene " + std::to_string(index) + " lists node " + std::to_string(root) + " twice");
            roots.push_back(root);
        }
        return roots;
    }

    ElementView view(int accessorIndex, int expectedType, const std::string& where) const {
        if (accessorIndex < 0 || std::size_t(accessorIndex) >= model_.accessors.size())
            fail(where + ": accessor " + std::to_string(accessorIndex) + " does not exist");
        const tinygltf::Accessor& acc = model_.accessors[std::size_t(accessorIndex)];
        const std::string a = where + ": accessor " + std::to_string(accessorIndex);
        if (acc.type != expectedType) fail(a + " has the wrong type");
        if (acc.sparse.isSparse) fail(a + " is sparse, which is not supported");
        if (acc.bufferView < 0 || std::size_t(acc.bufferView) >= model_.bufferViews.size())
            fail(a + " has no buffer view");
        const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
        const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
        if (componentSize <= 0 || components <= 0) fail(a + " has an unknown component type");
        if (acc.count == 0) fail(a + " has count 0 (the minimum is 1)");
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(acc.bufferView)];
        const std::string b = "buffer view " + std::to_string(acc.bufferView);
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size()) fail(b + " names a missing buffer");
        const std::uint64_t bufferBytes = model_.buffers[std::size_t(bv.buffer)].data.size();
        const std::uint64_t viewEnd = add(bv.byteOffset, bv.byteLength, b + ": byteOffset + byteLength");
        if (viewEnd > bufferBytes)
            fail(b + " (byteOffset " + str(bv.byteOffset) + ", byteLength " + str(bv.byteLength) + ") runs past the end of buffer " +
                 std::to_string(bv.buffer) + " (" + str(bufferBytes) + " bytes)");
        const std::uint64_t elementSize = std::uint64_t(componentSize) * std::uint64_t(components);
        if (bv.byteStride != 0 && (bv.byteStride < 4 || bv.byteStride > 252 || bv.byteStride % 4 != 0))
            fail(b + ": byteStride " + str(bv.byteStride) + " is not a multiple of 4 in 4..252");
        if (bv.byteStride != 0 && bv.byteStride < elementSize)
            fail(b + ": byteStride " + str(bv.byteStride) + " is smaller than the " + str(elementSize) + "-byte elements of " +
                 "accessor " + std::to_string(accessorIndex));
        if (acc.byteOffset % std::uint64_t(componentSize) != 0 ||
            add(bv.byteOffset, acc.byteOffset, a + ": offset") % std::uint64_t(componentSize) != 0)
            fail(a + ": byteOffset " + str(acc.byteOffset) + " is not aligned to its " + std::to_string(componentSize) + "-byte components");
        const std::uint64_t stride = bv.byteStride ? bv.byteStride : elementSize;
        const std::uint64_t span = add(mul(acc.count - 1, stride, a + ": count x stride"), elementSize, a + ": size");
        const std::uint64_t end = add(acc.byteOffset, span, a + ": byteOffset + size");
        if (end > bv.byteLength)
            fail(a + " (" + str(acc.count) + " elements of " + str(elementSize) + " bytes, stride " + str(stride) +
                 ", byteOffset " + str(acc.byteOffset) + ", " + str(end) + " bytes) runs past the end of " + b + " (" +
                 str(bv.byteLength) + " bytes)");
        ElementView v;
        v.data = model_.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset + acc.byteOffset;
        v.stride = stride;
        v.count = acc.count;
        v.componentType = acc.componentType;
        return v;
    }

private:
    std::string name_;
    const tinygltf::Model& model_;
};

// ---- planning: how many triangles, before anything is flattened --------------------------

glm::dmat4 localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
    if (node.rotation.size() == 4) {
        const std::vector<double>& q = node.rotation;  // glTF order: x, y, z, w
        m = m * glm::mat4_cast(glm::dquat(q[3], q[0], q[1], q[2]));
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
    return m;
}

struct NodeInstance {
    int node;
    glm::dmat4 world;
};

const char* modeName(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS (0)";
        case TINYGLTF_MODE_LINE: return "LINES (1)";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP (2)";
        case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP (3)";
        default: return "unknown";
    }
}

class GltfFlattener {
public:
    GltfFlattener(const std::string& name, const tinygltf::Model& model, const GltfLimits& limits)
        : name_(name), model_(model), limits_(limits), check_(name, model) {
        scene_.name = name;
        for (const tinygltf::Material& m : model.materials) {
            Material mat;
            const std::vector<double>& f = m.pbrMetallicRoughness.baseColorFactor;
            if (f.size() == 4) mat.baseColor = glm::vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
            mat.doubleSided = m.doubleSided;
            scene_.materials.push_back(mat);
        }
        defaultMaterial_ = std::uint32_t(scene_.materials.size());
        scene_.materials.push_back(Material{});
        if (!model.images.empty())
            scene_.warnings.push_back(name + ": " + std::to_string(model.images.size()) +
                                      (model.images.size() == 1 ? " image (texture) is" : " images (textures) are") +
                                      " not applied yet; the model is shaded with its base colour factors");
    }

    Scene run() {
        check_.checkExtensions();
        check_.checkCameras();
        const std::vector<int> parent = check_.checkNodes();
        const std::vector<NodeInstance> instances = walkHierarchy(check_.sceneRoots(parent));
        planTriangles(instances);
        for (const NodeInstance& i : instances) flattenNode(i);
        return std::move(scene_);
    }

private:
    // Every node of the scene with its world transform, depth first without recursion.
    std::vector<NodeInstance> walkHierarchy(const std::vector<int>& roots) const {
        std::vector<NodeInstance> out;
        std::vector<std::pair<NodeInstance, std::uint32_t>> stack;  // the node and its depth
        for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({{*it, glm::dmat4(1.0)}, 0});
        while (!stack.empty()) {
            const auto [parentInstance, depth] = stack.back();
            stack.pop_back();
            if (depth > limits_.maxHierarchyDepth)
                check_.fail("the node hierarchy is deeper than " + str(limits_.maxHierarchyDepth) + " levels (at node " +
                            std::to_string(parentInstance.node) + ")");
            const tinygltf::Node& node = model_.nodes[std::size_t(parentInstance.node)];
            const NodeInstance here{parentInstance.node, parentInstance.world * localTransform(node)};
            out.push_back(here);
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({{*c, here.world}, depth + 1});
        }
        return out;
    }

    std::uint64_t primitiveTriangles(const tinygltf::Primitive& prim, const std::string& where) const {
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
            check_.fail(where + ": primitive mode " + std::string(modeName(mode)) +
                        (mode > 6 ? " " + std::to_string(mode) : std::string()) +
                        " is not supported (only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN)");
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) check_.fail(where + ": no POSITION attribute");
        const ElementView positions = check_.view(pos->second, TINYGLTF_TYPE_VEC3, where + " POSITION");
        const std::uint64_t corners =
            prim.indices >= 0 ? check_.view(prim.indices, TINYGLTF_TYPE_SCALAR, where + " indices").count : positions.count;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (corners % 3 != 0) check_.fail(where + ": " + str(corners) + " indices is not a multiple of 3");
            return corners / 3;
        }
        return corners >= 3 ? corners - 2 : 0;
    }

    // The triangle total over every instance, checked against the 32-bit primitive ids and this
    // machine's memory before anything is flattened.
    void planTriangles(const std::vector<NodeInstance>& instances) const {
        std::vector<std::int64_t> meshTriangles(model_.meshes.size(), -1);
        std::uint64_t total = 0, meshInstances = 0;
        for (const NodeInstance& i : instances) {
            const int m = model_.nodes[std::size_t(i.node)].mesh;
            if (m < 0) continue;
            std::int64_t& count = meshTriangles[std::size_t(m)];
            if (count < 0) {
                std::uint64_t sum = 0;
                const tinygltf::Mesh& mesh = model_.meshes[std::size_t(m)];
                for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
                    sum = check_.add(sum, primitiveTriangles(mesh.primitives[p], "mesh " + str(std::uint64_t(m)) + " primitive " + str(p)),
                                     "the triangle count");
                count = std::int64_t(std::min<std::uint64_t>(sum, std::uint64_t(std::numeric_limits<std::int64_t>::max())));
            }
            total = check_.add(total, std::uint64_t(count), "the triangle count");
            ++meshInstances;
        }
        const std::string counted = str(total) + " triangles in " + str(meshInstances) + " mesh instances";
        if (total > kMaxTriangles)
            check_.fail("the scene has " + counted + ", more than the " + str(kMaxTriangles) + " that 32-bit primitive ids allow");
        const std::uint64_t bytes = check_.mul(total, kBytesPerTriangle, "the scene's size");
        const std::uint64_t limit = limits_.maxBytes ? limits_.maxBytes : physicalMemoryBytes();
        if (limit && bytes > limit)
            check_.fail("the scene has " + counted + ", which need " + str(bytes) + " bytes, more than the " + str(limit) +
                        " bytes of " + (limits_.maxBytes ? "the limit" : "this machine's memory") + " (over by " +
                        str(bytes - limit) + ")");
    }

    void flattenNode(const NodeInstance& instance) {
        const tinygltf::Node& node = model_.nodes[std::size_t(instance.node)];
        if (node.camera >= 0) takeCamera(node.camera, instance.world);
        if (node.mesh < 0) return;
        const tinygltf::Mesh& mesh = model_.meshes[std::size_t(node.mesh)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
            addPrimitive(std::uint32_t(instance.node), std::uint32_t(node.mesh), std::uint32_t(p), mesh.primitives[p],
                         instance.world);
    }

    void takeCamera(int cameraIndex, const glm::dmat4& world) {
        if (scene_.camera) return;
        const tinygltf::Camera& cam = model_.cameras[std::size_t(cameraIndex)];
        if (cam.type != "perspective") return;  // orthographic cameras fall back to the default view
        SceneCamera c;
        c.eye = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
        c.forward = glm::normalize(glm::dvec3(world * glm::dvec4(0, 0, -1, 0)));
        c.up = glm::normalize(glm::dvec3(world * glm::dvec4(0, 1, 0, 0)));
        c.yfovRadians = cam.perspective.yfov;
        if (!std::isfinite(c.eye.x) || !std::isfinite(c.eye.y) || !std::isfinite(c.eye.z) ||
            !std::isfinite(c.forward.x + c.forward.y + c.forward.z) || !std::isfinite(c.up.x + c.up.y + c.up.z))
            check_.fail("camera " + std::to_string(cameraIndex) + " has a non-finite or degenerate placement");
        scene_.camera = c;
    }

    std::vector<std::uint32_t> readIndices(const tinygltf::Primitive& prim, std::uint64_t vertexCount, const std::string& where) const {
        std::vector<std::uint32_t> indices;
        if (prim.indices < 0) {
            indices.resize(vertexCount);
            for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = std::uint32_t(i);
            return indices;
        }
        const ElementView iv = check_.view(prim.indices, TINYGLTF_TYPE_SCALAR, where + " indices");
        indices.resize(iv.count);
        for (std::size_t i = 0; i < iv.count; ++i) {
            const unsigned char* p = iv.data + i * iv.stride;
            switch (iv.componentType) {
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: indices[i] = *p; break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t x; std::memcpy(&x, p, 2); indices[i] = x; break; }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&indices[i], p, 4); break;
                default: check_.fail(where + ": indices must be unsigned 8, 16 or 32-bit integers");
            }
        }
        return indices;
    }

    void addPrimitive(std::uint32_t node, std::uint32_t meshIndex, std::uint32_t primIndex,
                      const tinygltf::Primitive& prim, const glm::dmat4& world) {
        const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        const ElementView positions = check_.view(prim.attributes.at("POSITION"), TINYGLTF_TYPE_VEC3, where + " POSITION");
        if (positions.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            check_.fail(where + ": POSITION must be float32 (quantized positions are not supported)");
        const std::vector<std::uint32_t> indices = readIndices(prim, positions.count, where);

        std::vector<std::uint32_t> corners;  // three per triangle, as TRIANGLES
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            corners = indices;
        } else {
            for (std::size_t i = 2; i < indices.size(); ++i) {
                if (mode == TINYGLTF_MODE_TRIANGLE_FAN) corners.insert(corners.end(), {indices[0], indices[i - 1], indices[i]});
                else if (i % 2 == 0) corners.insert(corners.end(), {indices[i - 2], indices[i - 1], indices[i]});
                else corners.insert(corners.end(), {indices[i - 1], indices[i - 2], indices[i]});
            }
        }

        std::vector<glm::vec3> worldPositions(positions.count);
        for (std::size_t i = 0; i < positions.count; ++i) {
            float xyz[3];
            std::memcpy(xyz, positions.data + i * positions.stride, sizeof(xyz));
            if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
                check_.fail(where + ": vertex " + std::to_string(i) + " has a non-finite position (" + std::to_string(xyz[0]) +
                            ", " + std::to_string(xyz[1]) + ", " + std::to_string(xyz[2]) + ")");
            worldPositions[i] = glm::vec3(world * glm::dvec4(xyz[0], xyz[1], xyz[2], 1.0));
        }

        std::uint32_t material = defaultMaterial_;
        if (prim.material >= 0) {
            if (std::size_t(prim.material) >= model_.materials.size())
                check_.fail(where + ": material " + std::to_string(prim.material) + " does not exist");
            material = std::uint32_t(prim.material);
        }

        // glTF: a node whose global transform mirrors (negative determinant) turns its
        // triangles' winding clockwise; swapping two corners keeps counter-clockwise the front.
        const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
        const std::uint32_t cullBackFace = scene_.materials[material].doubleSided ? 0u : 1u;
        for (std::size_t t = 0; t * 3 < corners.size(); ++t) {
            Triangle tri{};
            tri.cullBackFace = cullBackFace;
            glm::vec3* v[3] = {&tri.v0, mirrored ? &tri.v2 : &tri.v1, mirrored ? &tri.v1 : &tri.v2};
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t index = corners[t * 3 + std::size_t(k)];
                if (index >= positions.count)
                    check_.fail(where + ": index " + std::to_string(index) + " (triangle " + std::to_string(t) +
                                ") is out of range for " + str(positions.count) + " vertices");
                *v[k] = worldPositions[index];
            }
            // Never hit, so never traced. (A non-finite vertex gives a non-zero cross product:
            // such a triangle stays, for validateScene to refuse.)
            if (shared::triangleHasNoArea(tri.v0, tri.v1, tri.v2)) {
                ++scene_.degenerateTrianglesDropped;
                continue;
            }
            scene_.triangles.push_back(tri);
            scene_.sources.push_back(TriangleSource{node, meshIndex, primIndex, std::uint32_t(t)});
            scene_.materialOfTriangle.push_back(material);
        }
        touchTriangles(scene_);
    }

    std::string name_;
    const tinygltf::Model& model_;
    GltfLimits limits_;
    GltfChecker check_;
    Scene scene_;
    std::uint32_t defaultMaterial_ = 0;
};

Scene loadFromBytes(std::span<const unsigned char> bytes, const std::string& name, const std::string& baseDir,
                    bool readFiles, const GltfLimits& limits) {
    if (bytes.empty()) throw InputError(name + ": the file is empty");
    checkJsonNesting(bytes, name, limits);
    const tinygltf::Model model = parseGltf(bytes, name, baseDir, readFiles);
    Scene scene = GltfFlattener(name, model, limits).run();
    validateScene(scene);
    return scene;
}

}  // namespace

Scene loadGltf(const std::string& path, const GltfLimits& limits) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": no such file");
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path + ": cannot read the file (" + ec.message() + ")");
    const std::uint64_t limit = limits.maxBytes ? limits.maxBytes : physicalMemoryBytes();
    if (limit && size > limit)
        throw InputError(path + ": the file has " + str(size) + " bytes, more than the " + str(limit) + " bytes of memory");
    std::vector<unsigned char> bytes(size);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
        throw InputError(path + ": cannot read the file");
    const std::string baseDir = std::filesystem::path(path).parent_path().string();
    return loadFromBytes(bytes, path, baseDir.empty() ? "." : baseDir, true, limits);
}

Scene loadGltfFromMemory(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits) {
    return loadFromBytes(bytes, name, "", false, limits);
}

}  // namespace dacrt
