#include "core/gltf_loader.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <string_view>
#include <thread>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/errors.hpp"
#include "core/gltf_accessors.hpp"
#include "core/gltf_animation.hpp"
#include "core/gltf_compression.hpp"
#include "core/gltf_container.hpp"
#include "core/gltf_json_rules.hpp"
#include "core/gltf_materials.hpp"
#include "core/input_file.hpp"
#include "core/json_nesting.hpp"
#include "core/mapped_memory.hpp"
#include "core/system_memory.hpp"
#include "core/timing.hpp"
#include "core/triangle_rules.hpp"

namespace dacrt {
namespace {

// What one flattened triangle costs while the scene is built and traced: the triangle, its
// provenance and material (Scene), its bounds (allTriangleBounds), and at most its corners'
// normals, texture coordinates and colours (CornerAttributes).
constexpr std::uint64_t kBytesPerTriangle =
    sizeof(Triangle) + sizeof(TriangleSource) + 4 + sizeof(Bounds) + 3 * (sizeof(glm::vec3) + sizeof(glm::vec2) + sizeof(glm::vec4));
// Primitive ids are 32-bit and kMissPrim is reserved.
constexpr std::uint64_t kMaxTriangles = std::numeric_limits<std::uint32_t>::max() - 1;

using gltf::str;

// A scene or camera chosen by number: the choice as an index when it is all digits (and small).
std::optional<int> indexChoice(const std::string& choice) {
    if (choice.empty() || choice.size() >= 10 || choice.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    return std::stoi(choice);
}

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

// tinygltf reads a .glb's version and ignores it; a version other than 2 is another format.
void checkGlbVersion(std::span<const unsigned char> bytes, const std::string& name) {
    if (!isBinaryGltf(bytes) || bytes.size() < 8) return;  // a short header is the parser's to refuse
    if (const std::uint32_t version = readU32(bytes, 4); version != 2)
        throw InputError(name + ": the GLB header's version is " + str(version) + ", not 2 (glTF 2.0's binary container)");
}

// tinygltf copies a .glb's BIN chunk by the length the chunk declares, without holding it to
// the bytes that follow (the glb fuzzer read past a file's end this way): every chunk's
// declared length is checked against what is left of the file first.
void checkGlbChunks(std::span<const unsigned char> bytes, const std::string& name) {
    if (!isBinaryGltf(bytes) || bytes.size() < 12 || readU32(bytes, 8) != bytes.size()) return;  // the parser's to refuse
    std::size_t at = 12;
    for (int k = 0; at < bytes.size(); ++k) {
        if (bytes.size() - at < 8)
            throw InputError(name + ": the GLB's chunk " + str(k) + " has " + str(bytes.size() - at) +
                             " bytes, fewer than a chunk header's 8");
        const std::uint64_t length = readU32(bytes, at);
        const std::uint32_t type = readU32(bytes, at + 4);
        const char* kind = type == 0x4E4F534Au ? " (JSON)" : type == 0x004E4942u ? " (BIN)" : "";
        if (length > bytes.size() - at - 8)
            throw InputError(name + ": the GLB's chunk " + str(k) + kind + " declares " + str(length) + " bytes, but " +
                             str(bytes.size() - at - 8) + " follow its header");
        at += 8 + std::size_t(length);
    }
}

// ---- parsing ----------------------------------------------------------------------------

// Memory input never reads files: an external buffer is reported as missing.
bool noFileExists(const std::string&, void*) { return false; }
std::string keepPath(const std::string& path, void*) { return path; }
bool noFileRead(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
    if (err) *err += "external file '" + path + "' is not read from memory input\n";
    return false;
}

// External buffers read as the file itself is: regular files only, within this machine's
// memory (tinygltf's own reader opens a FIFO and waits, or reads a device without end).
bool boundedFileRead(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
    try {
        *out = readRegularInput(path, physicalMemoryBytes());
        return true;
    } catch (const InputError& e) {
        if (err) *err += std::string(e.what()) + "\n";
        return false;
    }
}

tinygltf::Model parseGltf(std::span<const unsigned char> bytes, const std::string& name, const std::string& baseDir,
                          bool readFiles) {
    if (bytes.size() > std::numeric_limits<unsigned int>::max())
        throw InputError(name + ": " + str(bytes.size()) + " bytes is more than the glTF parser takes (4 GiB)");
    tinygltf::TinyGLTF reader;
    reader.SetStoreOriginalJSONForExtrasAndExtensions(false);
    reader.SetImageLoader(gltf::keepEncodedImage, nullptr);
    if (!readFiles) reader.SetFsCallbacks(tinygltf::FsCallbacks{noFileExists, keepPath, noFileRead, nullptr, nullptr});
    else
        reader.SetFsCallbacks(
            tinygltf::FsCallbacks{tinygltf::FileExists, tinygltf::ExpandFilePath, boundedFileRead, tinygltf::WriteWholeFile, nullptr});
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

// Extensions dacrt reads; a file may require them. Any other required extension is refused.
constexpr std::array<std::string_view, 7> kReadExtensions{"KHR_mesh_quantization", "EXT_meshopt_compression",
                                                          "KHR_meshopt_compression", "KHR_draco_mesh_compression",
                                                          "KHR_texture_transform", "KHR_lights_punctual",
                                                          "KHR_materials_pbrSpecularGlossiness"};
bool readsExtension(const std::string& e) {
    return std::find(kReadExtensions.begin(), kReadExtensions.end(), e) != kReadExtensions.end();
}

std::string joined(const std::vector<std::string>& items) {
    std::string out;
    for (const std::string& e : items) out += (out.empty() ? "" : ", ") + e;
    return out;
}

class GltfChecker {
public:
    GltfChecker(const gltf::AccessorReader& reader) : reader_(reader), model_(reader.model()) {}

    [[noreturn]] void fail(const std::string& what) const { reader_.fail(what); }
    std::uint64_t add(std::uint64_t a, std::uint64_t b, const std::string& what) const { return reader_.add(a, b, what); }
    std::uint64_t mul(std::uint64_t a, std::uint64_t b, const std::string& what) const { return reader_.mul(a, b, what); }

    // Required extensions dacrt does not read are refused by name; used ones it ignores are
    // named in one warning.
    void checkExtensions(std::vector<std::string>& warnings) const {
        std::vector<std::string> refused, ignored;
        for (const std::string& e : model_.extensionsRequired)
            if (!readsExtension(e)) refused.push_back(e);
        if (!refused.empty())
            fail("the file requires the extension" + std::string(refused.size() > 1 ? "s " : " ") + joined(refused) +
                 ", which dacrt does not support (it reads " + joined({kReadExtensions.begin(), kReadExtensions.end()}) + ")");
        for (const std::string& e : model_.extensionsUsed)
            if (!readsExtension(e)) ignored.push_back(e);
        if (!ignored.empty())
            warnings.push_back(reader_.name() + ": ignored the extension" + std::string(ignored.size() > 1 ? "s " : " ") +
                               joined(ignored) + " (used, not required)");
    }

    bool uses(const char* extension) const {
        return std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), extension) != model_.extensionsUsed.end() ||
               std::find(model_.extensionsRequired.begin(), model_.extensionsRequired.end(), extension) != model_.extensionsRequired.end();
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
    std::vector<int> checkNodes(std::vector<std::string>& warnings) const {
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
                // Exported files round their quaternions (Khronos' own Cameras sample: 1.000232);
                // within 1% of unit length the rotation is meant, and is normalized.
                if (!(std::abs(len - 1.0) <= 1e-2))
                    fail(where + ": the rotation quaternion has length " + std::to_string(len) + ", not 1");
                if (std::abs(len - 1.0) > 1e-5)
                    warnings.push_back(reader_.name() + ": " + where + ": the rotation quaternion has length " +
                                       std::to_string(len) + "; normalized");
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

    // Which scene to load: `choice` is an index or a scene name; empty: the file's default
    // scene (or the first). -1 when the file has no scenes.
    int chooseScene(const std::string& choice) const {
        if (model_.scenes.empty()) {
            if (!choice.empty()) fail("the file has no scenes, so --scene " + choice + " names none");
            return -1;
        }
        if (choice.empty()) {
            const int index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
            if (index >= int(model_.scenes.size())) fail("default scene " + std::to_string(index) + " does not exist");
            return index;
        }
        for (std::size_t i = 0; i < model_.scenes.size(); ++i)
            if (model_.scenes[i].name == choice) return int(i);
        if (const std::optional<int> index = indexChoice(choice); index && *index < int(model_.scenes.size())) return *index;
        std::vector<std::string> names;
        for (std::size_t i = 0; i < model_.scenes.size(); ++i) names.push_back(str(i) + (model_.scenes[i].name.empty() ? "" : " '" + model_.scenes[i].name + "'"));
        fail("no scene is called or numbered '" + choice + "' (the file has " + joined(names) + ")");
    }

    // The roots of the scene (or, with no scene, every parentless node).
    std::vector<int> sceneRoots(const std::vector<int>& parent, int index) const {
        std::vector<int> roots;
        if (index < 0) {
            for (std::size_t i = 0; i < parent.size(); ++i)
                if (parent[i] < 0) roots.push_back(int(i));
            return roots;
        }
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

private:
    const gltf::AccessorReader& reader_;
    const tinygltf::Model& model_;
};

// ---- planning: how many triangles, before anything is flattened --------------------------

// The node's transform, its animated properties (pose) in place of its own. An animated node
// has no matrix (readAnimations refuses one); properties neither set nor animated are skipped,
// not multiplied as identities, so a still node's transform is what it always was.
glm::dmat4 localTransform(const tinygltf::Node& node, const gltf::NodePose& pose) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
    glm::dmat4 m(1.0);
    if (pose.translation) m = glm::translate(m, *pose.translation);
    else if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
    std::optional<glm::dquat> r = pose.rotation;
    if (!r && node.rotation.size() == 4) {
        const std::vector<double>& q = node.rotation;  // glTF order: x, y, z, w
        r = glm::dquat(q[3], q[0], q[1], q[2]);
    }
    if (r) {
        if (std::abs(glm::length(*r) - 1.0) > 1e-12) r = glm::normalize(*r);  // within 1% (checkNodes)
        m = m * glm::mat4_cast(*r);
    }
    if (pose.scale) m = glm::scale(m, *pose.scale);
    else if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
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

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

const std::string kPosition = "POSITION", kNormal = "NORMAL", kColor = "COLOR_0";
std::string texCoordName(std::uint32_t set) { return "TEXCOORD_" + std::to_string(set); }

}  // namespace

// What a file's every frame shares: the parsed model, its checks' results, the materials and
// textures (decoded once), the animations and the primitives' data (read once, on first use).
struct GltfDocument::Impl {
    std::string name;
    GltfLimits limits;
    gltf::PreparedContainer prepared;
    tinygltf::Model model;
    std::unique_ptr<gltf::AccessorReader> reader;
    std::vector<int> parent;                 // each node's, -1 for none
    Scene shared;                            // materials (the default last), textures, the file's warnings
    std::vector<gltf::Animation> animations;
    std::vector<GltfAnimationInfo> animationInfo;
    std::map<std::pair<std::uint32_t, std::uint32_t>, gltf::PrimitiveData> primitives;  // by (mesh, primitive)
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> corners;  // their triangleCorners
    unsigned threads = 0;               // that flatten the triangles; 0: every core
    std::unique_ptr<ThreadPool> pool;   // made on first use, kept from frame to frame

    std::uint64_t memoryLimit() const { return limits.maxBytes ? limits.maxBytes : physicalMemoryBytes(); }
    ThreadPool& threadPool() {
        if (!pool) pool = std::make_unique<ThreadPool>(threads ? threads : std::max(1u, std::thread::hardware_concurrency()));
        return *pool;
    }
};

namespace {

class GltfFlattener {
public:
    GltfFlattener(GltfDocument::Impl& document, const GltfSelection& selection, const std::function<void(double)>& onProgress)
        : document_(document), reader_(*document.reader), model_(document.model), limits_(document.limits),
          selection_(selection), onProgress_(onProgress), check_(*document.reader) {
        scene_.name = document.name;
    }

    Scene run() {
        auto since = Clock::now();
        const int sceneIndex = check_.chooseScene(selection_.scene);
        const int animation = gltf::chooseAnimation(document_.animations, selection_.animation, reader_);
        pose_ = gltf::poseAt(document_.animations, animation, selection_.time, model_.nodes.size());
        const std::vector<NodeInstance> instances = walkHierarchy(check_.sceneRoots(document_.parent, sceneIndex));
        plannedTriangles_ = planTriangles(instances);
        phases_.pose = lap(since);
        // Filled to at most the planned count (less the degenerate triangles): never regrown.
        reserveMapped(scene_.triangles, plannedTriangles_);
        reserveMapped(scene_.sources, plannedTriangles_);
        reserveMapped(scene_.materialOfTriangle, plannedTriangles_);
        phases_.mapMemory = lap(since);
        scene_.materials = document_.shared.materials;
        scene_.textures = document_.shared.textures;
        scene_.warnings = document_.shared.warnings;
        defaultMaterial_ = std::uint32_t(scene_.materials.size() - 1);
        for (const NodeInstance& i : instances) flattenNode(i);
        scene_.setupPhasesMs = {{"pose", phases_.pose}, {"map_memory", phases_.mapMemory}, {"primitives", phases_.primitives},
                                {"vertices", phases_.vertices}, {"triangles", phases_.triangles}};
        takeInventory(sceneIndex);
        if (unweightedVertices_)
            scene_.warnings.push_back(reader_.name() + ": " + str(unweightedVertices_) +
                                      " skinned vertices have no joint weight; they follow their skin's first joint");
        return std::move(scene_);
    }

private:
    std::uint64_t memoryLimit() const { return document_.memoryLimit(); }

    // The milliseconds since `since`, which moves to now.
    static double lap(Clock::time_point& since) {
        const double ms = msSince(since);
        since = Clock::now();
        return ms;
    }

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
            const NodeInstance here{parentInstance.node,
                                    parentInstance.world * localTransform(node, pose_[std::size_t(parentInstance.node)])};
            out.push_back(here);
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({{*c, here.world}, depth + 1});
        }
        return out;
    }

    static int modeOf(const tinygltf::Primitive& prim) { return prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode; }

    // The triangles a primitive declares, from its accessors' counts (a Draco primitive's
    // accessors declare the decoded counts).
    std::uint64_t primitiveTriangles(const tinygltf::Primitive& prim, const std::string& where) const {
        const int mode = modeOf(prim);
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
            check_.fail(where + ": primitive mode " + std::string(modeName(mode)) +
                        (mode > 6 ? " " + std::to_string(mode) : std::string()) +
                        " is not supported (only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN)");
        auto pos = prim.attributes.find(kPosition);
        if (pos == prim.attributes.end()) check_.fail(where + ": no POSITION attribute");
        // Counts are trusted only once their accessors' ranges are checked.
        const std::uint64_t vertices = reader_.checkedCount(pos->second, {TINYGLTF_TYPE_VEC3}, where + " POSITION");
        const std::uint64_t corners =
            prim.indices >= 0 ? reader_.checkedCount(prim.indices, {TINYGLTF_TYPE_SCALAR}, where + " indices") : vertices;
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (corners % 3 != 0) check_.fail(where + ": " + str(corners) + " indices is not a multiple of 3");
            return corners / 3;
        }
        return corners >= 3 ? corners - 2 : 0;
    }

    // The triangle total over every instance, checked against the 32-bit primitive ids and this
    // machine's memory before anything is flattened. Returns it.
    std::uint64_t planTriangles(const std::vector<NodeInstance>& instances) const {
        std::vector<std::int64_t> meshTriangles(model_.meshes.size(), -1);
        std::uint64_t total = 0, meshInstances = 0;
        for (const NodeInstance& i : instances) {
            const int m = model_.nodes[std::size_t(i.node)].mesh;
            if (m < 0) continue;
            std::int64_t& count = meshTriangles[std::size_t(m)];
            if (count < 0) count = std::int64_t(std::min<std::uint64_t>(meshTriangleCount(std::size_t(m)), std::uint64_t(std::numeric_limits<std::int64_t>::max())));
            total = check_.add(total, std::uint64_t(count), "the triangle count");
            ++meshInstances;
        }
        const std::string counted = str(total) + " triangles in " + str(meshInstances) + " mesh instances";
        if (total > kMaxTriangles)
            check_.fail("the scene has " + counted + ", more than the " + str(kMaxTriangles) + " that 32-bit primitive ids allow");
        const std::uint64_t bytes = check_.mul(total, kBytesPerTriangle, "the scene's size");
        const std::uint64_t limit = memoryLimit();
        if (limit && bytes > limit)
            check_.fail("the scene has " + counted + ", which need " + str(bytes) + " bytes, more than the " + str(limit) +
                        " bytes of " + (limits_.maxBytes ? "the limit" : "this machine's memory") + " (over by " +
                        str(bytes - limit) + ")");
        return total;
    }

    std::uint64_t meshTriangleCount(std::size_t m) const {
        std::uint64_t sum = 0;
        const tinygltf::Mesh& mesh = model_.meshes[m];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
            sum = check_.add(sum, primitiveTriangles(mesh.primitives[p], "mesh " + str(m) + " primitive " + str(p)), "the triangle count");
        return sum;
    }

    void flattenNode(const NodeInstance& instance) {
        const tinygltf::Node& node = model_.nodes[std::size_t(instance.node)];
        if (node.camera >= 0) placeCamera(instance, node.camera);
        placeLight(instance, node);
        if (node.mesh < 0) return;
        const tinygltf::Mesh& mesh = model_.meshes[std::size_t(node.mesh)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
            addPrimitive(std::uint32_t(instance.node), std::uint32_t(node.mesh), std::uint32_t(p), mesh.primitives[p],
                         instance.world);
    }

    void placeCamera(const NodeInstance& instance, int cameraIndex) {
        const tinygltf::Camera& cam = model_.cameras[std::size_t(cameraIndex)];
        SceneCamera c;
        const glm::dmat4& world = instance.world;
        c.eye = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
        c.forward = glm::normalize(glm::dvec3(world * glm::dvec4(0, 0, -1, 0)));
        c.up = glm::normalize(glm::dvec3(world * glm::dvec4(0, 1, 0, 0)));
        c.name = cam.name;
        c.cameraIndex = cameraIndex;
        c.node = instance.node;
        if (cam.type == "perspective") {
            c.yfovRadians = cam.perspective.yfov;
        } else {
            c.projection = Projection::Orthographic;
            // The node's scale along y scales the view like the geometry it frames.
            c.ymag = std::abs(cam.orthographic.ymag) * glm::length(glm::dvec3(world * glm::dvec4(0, 1, 0, 0)));
        }
        if (!finite3(c.eye) || !finite3(c.forward) || !finite3(c.up) || !std::isfinite(c.ymag) ||
            (c.projection == Projection::Orthographic && !(c.ymag > 0.0)))
            check_.fail("camera " + std::to_string(cameraIndex) + " (node " + std::to_string(instance.node) +
                        ") has a non-finite or degenerate placement");
        scene_.cameras.push_back(c);
        if (!scene_.camera) scene_.camera = c;
    }

    void placeLight(const NodeInstance& instance, const tinygltf::Node& node) {
        auto ext = node.extensions.find("KHR_lights_punctual");
        if (ext == node.extensions.end() || !ext->second.IsObject() || !ext->second.Has("light")) return;
        const tinygltf::Value& index = ext->second.Get("light");
        const std::string where = "node " + std::to_string(instance.node) + ": KHR_lights_punctual";
        if (!index.IsNumber() || index.GetNumberAsDouble() < 0 || index.GetNumberAsDouble() >= double(model_.lights.size()))
            check_.fail(where + " names a light that does not exist");
        const std::size_t li = std::size_t(index.GetNumberAsDouble());
        const tinygltf::Light& l = model_.lights[li];
        Light light;
        light.name = l.name;
        light.node = std::uint32_t(instance.node);
        if (l.type == "point") light.type = LightType::Point;
        else if (l.type == "spot") light.type = LightType::Spot;
        else if (l.type == "directional") light.type = LightType::Directional;
        else check_.fail("light " + str(li) + ": type '" + l.type + "' is none of point, spot, directional");
        if (l.color.size() == 3) light.color = glm::vec3(float(l.color[0]), float(l.color[1]), float(l.color[2]));
        light.intensity = float(l.intensity);
        light.range = float(l.range);
        light.innerConeAngle = float(l.spot.innerConeAngle);
        light.outerConeAngle = float(l.spot.outerConeAngle);
        if (!std::isfinite(light.color.x + light.color.y + light.color.z + light.intensity + light.range) || light.intensity < 0 ||
            light.range < 0)
            check_.fail("light " + str(li) + ": colour, intensity and range must be finite and not negative");
        if (light.type == LightType::Spot &&
            !(light.innerConeAngle >= 0 && light.innerConeAngle < light.outerConeAngle && light.outerConeAngle <= M_PI / 2 + 1e-6))
            check_.fail("light " + str(li) + ": a spot light needs 0 <= innerConeAngle < outerConeAngle <= pi/2");
        light.position = glm::dvec3(instance.world * glm::dvec4(0, 0, 0, 1));
        light.direction = glm::dvec3(instance.world * glm::dvec4(0, 0, -1, 0));
        const double length = glm::length(light.direction);
        if (!finite3(light.position) || !(length > 0.0) || !std::isfinite(length))
            check_.fail(where + ": the light's placement is non-finite or degenerate");
        light.direction /= length;
        scene_.lights.push_back(light);
    }

    // The attributes the shading reads, for a primitive whose material is `material`.
    std::vector<std::string> wantedAttributes(std::uint32_t material) const {
        std::vector<std::string> names{kPosition, kNormal, kColor};
        if (scene_.materials[material].baseColorTexture.texture >= 0)
            names.push_back(texCoordName(scene_.materials[material].baseColorTexture.texCoord));
        return names;
    }

    gltf::PrimitiveData readPrimitive(const tinygltf::Primitive& prim, const std::vector<std::string>& wanted,
                                      const std::string& where) const {
        if (gltf::usesDraco(prim)) return gltf::decodeDracoPrimitive(reader_, prim, wanted, where);
        gltf::PrimitiveData data;
        if (prim.indices >= 0) {
            data.indexed = true;
            data.indices = reader_.readIndices(prim.indices, where + " indices");
        }
        const std::uint64_t vertices = reader_.checkedCount(prim.attributes.at(kPosition), {TINYGLTF_TYPE_VEC3}, where + " POSITION");
        for (const std::string& name : wanted) {
            auto a = prim.attributes.find(name);
            if (a == prim.attributes.end()) continue;
            const std::string w = where + " " + name;
            const std::uint64_t count =
                reader_.accessor(a->second, {TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, w).count;
            if (count != vertices)
                check_.fail(w + ": accessor " + std::to_string(a->second) + " has " + str(count) + " elements, POSITION has " + str(vertices));
            if (name == kColor) data.attributes[name] = reader_.readVectors(a->second, {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, w);
            else if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0)
                data.attributes[name] = reader_.readVectors(a->second, {TINYGLTF_TYPE_VEC4}, w);
            else if (name.rfind("TEXCOORD_", 0) == 0) data.attributes[name] = reader_.readVectors(a->second, {TINYGLTF_TYPE_VEC2}, w);
            else data.attributes[name] = reader_.readVectors(a->second, {TINYGLTF_TYPE_VEC3}, w);
        }
        return data;
    }

    // POSITION must be float unless the file uses KHR_mesh_quantization, which allows
    // (normalized) 8 and 16-bit integers.
    void checkPositionType(const tinygltf::Primitive& prim, const std::string& where) const {
        const tinygltf::Accessor& acc = reader_.accessor(prim.attributes.at(kPosition), {TINYGLTF_TYPE_VEC3}, where + " POSITION");
        const int t = acc.componentType;
        if (t == TINYGLTF_COMPONENT_TYPE_FLOAT) return;
        const bool quantizable = t == TINYGLTF_COMPONENT_TYPE_BYTE || t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                 t == TINYGLTF_COMPONENT_TYPE_SHORT || t == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (!quantizable) check_.fail(where + ": POSITION must be float32, or 8 or 16-bit integers under KHR_mesh_quantization");
        if (!check_.uses("KHR_mesh_quantization"))
            check_.fail(where + ": POSITION is quantized (integer components), which needs the extension KHR_mesh_quantization the file does not declare");
    }

    // Grows an attribute array to one entry per triangle so far, with its default (room for
    // the planned triangles made once).
    template <typename T>
    void fillTo(std::vector<std::array<T, 3>>& v, std::size_t n, const T& value) const {
        if (v.empty()) reserveMapped(v, plannedTriangles_);
        if (v.size() < n) v.resize(n, {value, value, value});
    }

    // The primitive's indices and attributes, read once per document: the shading's, a skin's
    // JOINTS_n and WEIGHTS_n, and each morph target's POSITION and NORMAL offsets (as
    // "TARGET<i>:POSITION"). A Draco mesh placed by many nodes is decoded once too.
    const gltf::PrimitiveData& primitiveData(std::uint32_t meshIndex, std::uint32_t primIndex, const tinygltf::Primitive& prim,
                                             std::uint32_t material, const std::string& where) {
        const auto key = std::make_pair(meshIndex, primIndex);
        if (auto cached = document_.primitives.find(key); cached != document_.primitives.end()) return cached->second;
        std::vector<std::string> wanted = wantedAttributes(material);
        for (const auto& [name, accessor] : prim.attributes)
            if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0) wanted.push_back(name);
        gltf::PrimitiveData data = readPrimitive(prim, wanted, where);
        if (!prim.targets.empty() && gltf::usesDraco(prim))
            check_.fail(where + ": morph targets of a Draco-compressed primitive are not read");
        const std::size_t vertices = data.attributes.count(kPosition) ? data.attributes.at(kPosition).size() : 0;
        for (std::size_t t = 0; t < prim.targets.size(); ++t)
            for (const std::string& name : {kPosition, kNormal}) {
                auto a = prim.targets[t].find(name);
                if (a == prim.targets[t].end()) continue;
                const std::string w = where + " morph target " + str(t) + " " + name;
                // Counted before read: a target's count is declared, not bounded by its bytes.
                if (const std::uint64_t count = reader_.checkedCount(a->second, {TINYGLTF_TYPE_VEC3}, w); count != vertices)
                    check_.fail(w + ": accessor " + std::to_string(a->second) + " has " + str(count) +
                                " elements, POSITION has " + str(vertices));
                std::vector<glm::dvec4> offsets = reader_.readVectors(a->second, {TINYGLTF_TYPE_VEC3}, w);
                data.attributes["TARGET" + std::to_string(t) + ":" + name] = std::move(offsets);
            }
        return document_.primitives.emplace(key, std::move(data)).first->second;
    }

    // The morph-target weights of a node's mesh at this instant: animated, else the node's,
    // else the mesh's, else zeros; as many as the mesh's primitives have targets.
    std::vector<double> morphWeights(std::uint32_t nodeIndex, const tinygltf::Mesh& mesh, std::size_t targets,
                                     const std::string& where) const {
        const tinygltf::Node& node = model_.nodes[nodeIndex];
        const std::optional<std::vector<double>>& animated = pose_[nodeIndex].weights;
        const std::vector<double>& w = animated ? *animated : !node.weights.empty() ? node.weights : mesh.weights;
        if (w.empty()) return std::vector<double>(targets, 0.0);
        if (w.size() != targets)
            check_.fail(where + ": " + str(w.size()) + " morph weights for " + str(targets) + " morph targets");
        for (double x : w)
            if (!std::isfinite(x)) check_.fail(where + ": a morph weight is not finite");
        return w;
    }

    // A skin's joint matrices at this instant: each joint's world transform times its inverse
    // bind matrix. (glTF ignores the skinned mesh node's own transform.)
    std::vector<glm::dmat4> jointMatrices(int skinIndex, const std::string& where) {
        if (skinIndex < 0 || std::size_t(skinIndex) >= model_.skins.size())
            check_.fail(where + ": skin " + std::to_string(skinIndex) + " does not exist");
        const tinygltf::Skin& skin = model_.skins[std::size_t(skinIndex)];
        const std::string w = "skin " + std::to_string(skinIndex);
        if (skin.joints.empty()) check_.fail(w + " has no joints");
        std::vector<glm::dmat4> inverseBind(skin.joints.size(), glm::dmat4(1.0));
        if (skin.inverseBindMatrices >= 0) {
            inverseBind = reader_.readMatrices(skin.inverseBindMatrices, w + " inverseBindMatrices");
            if (inverseBind.size() < skin.joints.size())
                check_.fail(w + ": " + str(inverseBind.size()) + " inverse bind matrices for " + str(skin.joints.size()) + " joints");
        }
        std::vector<glm::dmat4> out(skin.joints.size());
        for (std::size_t j = 0; j < skin.joints.size(); ++j) {
            const int joint = skin.joints[j];
            if (joint < 0 || std::size_t(joint) >= model_.nodes.size())
                check_.fail(w + " names joint node " + std::to_string(joint) + ", which does not exist");
            out[j] = nodeWorld(std::size_t(joint)) * inverseBind[j];
            for (int c = 0; c < 4; ++c)
                if (!finite3(glm::dvec3(out[j][c])) || !std::isfinite(out[j][c][3]))
                    check_.fail(w + ": joint " + str(j) + " has a non-finite matrix");
        }
        return out;
    }

    // Any node's world transform at this instant (a joint may lie outside the loaded scene, so
    // its chain of ancestors is unbounded by the scene's depth limit): up the chain to the first
    // ancestor already known, then down it, without recursion.
    const glm::dmat4& nodeWorld(std::size_t node) {
        if (worlds_.empty()) worlds_.resize(model_.nodes.size());
        std::vector<std::size_t> chain;  // the node and its ancestors not yet known, nearest first
        for (int at = int(node); at >= 0 && !worlds_[std::size_t(at)]; at = document_.parent[std::size_t(at)])
            chain.push_back(std::size_t(at));
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const glm::dmat4 local = localTransform(model_.nodes[*it], pose_[*it]);
            const int parent = document_.parent[*it];
            worlds_[*it] = parent < 0 ? glm::dmat4(1.0) * local : *worlds_[std::size_t(parent)] * local;
        }
        return *worlds_[node];
    }

    // Each vertex's skinning matrix: its joints' matrices weighted over every JOINTS_n/WEIGHTS_n
    // set (weights normalized to sum 1; a vertex with none keeps the first joint's).
    std::vector<glm::dmat4> vertexSkinning(const gltf::PrimitiveData& data, const std::vector<glm::dmat4>& joints,
                                           std::size_t vertices, const std::string& where) {
        std::vector<glm::dmat4> out(vertices, glm::dmat4(0.0));
        std::vector<double> total(vertices, 0.0);
        bool anySet = false;
        for (int set = 0;; ++set) {
            auto j = data.attributes.find("JOINTS_" + std::to_string(set));
            auto w = data.attributes.find("WEIGHTS_" + std::to_string(set));
            if (j == data.attributes.end() && w == data.attributes.end()) break;
            if (j == data.attributes.end() || w == data.attributes.end())
                check_.fail(where + ": JOINTS_" + std::to_string(set) + " and WEIGHTS_" + std::to_string(set) + " come in pairs");
            anySet = true;
            for (std::size_t v = 0; v < vertices; ++v)
                for (int k = 0; k < 4; ++k) {
                    const double weight = w->second[v][k];
                    if (!(weight >= 0.0) || !std::isfinite(weight))
                        check_.fail(where + ": vertex " + str(v) + " has a negative or non-finite skin weight");
                    if (weight == 0.0) continue;
                    const double joint = j->second[v][k];
                    if (!(joint >= 0.0) || joint >= double(joints.size()) || joint != std::floor(joint))
                        check_.fail(where + ": vertex " + str(v) + " names joint " + std::to_string(joint) + "; the skin has " +
                                    str(joints.size()));
                    out[v] += weight * joints[std::size_t(joint)];
                    total[v] += weight;
                }
        }
        if (!anySet) check_.fail(where + ": a skinned mesh's primitive has no JOINTS_0 and WEIGHTS_0");
        for (std::size_t v = 0; v < vertices; ++v) {
            if (total[v] > 0.0) {
                if (total[v] != 1.0) out[v] /= total[v];
            } else {
                out[v] = joints.front();
                ++unweightedVertices_;
            }
        }
        return out;
    }

    // A primitive's shading inputs, each checked to hold one element per vertex (null where absent).
    struct VertexShading {
        const std::vector<glm::dvec4>* normals = nullptr;
        const std::vector<glm::dvec4>* colors = nullptr;
        const std::vector<glm::dvec4>* texCoords = nullptr;
        bool colorHasAlpha = false;
    };

    // A primitive's vertices and normals in the mesh's space, morph targets' offsets weighted in
    // (positions: empty where no offset moves them, the primitive's own then read in place).
    struct MorphedVertices {
        std::vector<glm::dvec3> positions;
        std::vector<glm::dvec3> normals;
    };

    // A primitive's vertices placed in the world at this instant, with what the corners' normals
    // and winding need: the normals before placing, and what placed each vertex (its skinning
    // matrix when skinned, else the node's transform).
    struct PlacedVertices {
        std::vector<glm::vec3> worldPositions;
        std::vector<glm::dvec3> localNormals;
        bool skinned = false;
        std::vector<glm::dmat4> skinning;
        glm::dmat3 nodeNormalMatrix{1.0};
        bool nodeMirrored = false;
    };

    // One primitive of a node's mesh into the scene: its triangles as placed at this instant.
    void addPrimitive(std::uint32_t node, std::uint32_t meshIndex, std::uint32_t primIndex,
                      const tinygltf::Primitive& prim, const glm::dmat4& world) {
        const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
        int mode = modeOf(prim);
        auto since = Clock::now();
        const std::uint32_t material = primitiveMaterial(prim, where);
        checkPositionType(prim, where);
        const gltf::PrimitiveData& data = primitiveData(meshIndex, primIndex, prim, material, where);
        if (data.trianglesListed) mode = TINYGLTF_MODE_TRIANGLES;
        if (!data.attributes.count(kPosition)) check_.fail(where + ": no POSITION data");
        const std::vector<std::uint32_t>& corners = primitiveCorners(meshIndex, primIndex, mode, data, where);
        const VertexShading shading = vertexShading(prim, data, material, where);
        phases_.primitives += lap(since);
        const PlacedVertices placed = placeVertices(node, meshIndex, prim, data, shading.normals, world, where);
        phases_.vertices += lap(since);
        addTriangles(TriangleSource{node, meshIndex, primIndex, 0}, material, corners, placed, shading, where);
        touchTriangles(scene_);
        phases_.triangles += lap(since);
        assembledTriangles_ += corners.size() / 3;
        if (onProgress_ && plannedTriangles_) onProgress_(double(assembledTriangles_) / double(plannedTriangles_));
    }

    // The primitive's material, the default one when it names none.
    std::uint32_t primitiveMaterial(const tinygltf::Primitive& prim, const std::string& where) const {
        std::uint32_t material = defaultMaterial_;
        if (prim.material >= 0) {
            if (std::size_t(prim.material) >= model_.materials.size())
                check_.fail(where + ": material " + std::to_string(prim.material) + " does not exist");
            material = std::uint32_t(prim.material);
        }
        return material;
    }

    // The primitive's triangleCorners, made once per document (an indexed list's are its indices).
    const std::vector<std::uint32_t>& primitiveCorners(std::uint32_t meshIndex, std::uint32_t primIndex, int mode,
                                                       const gltf::PrimitiveData& data, const std::string& where) {
        if (mode == TINYGLTF_MODE_TRIANGLES && data.indexed) {  // the indices themselves
            if (data.indices.size() % 3 != 0) check_.fail(where + ": " + str(data.indices.size()) + " indices is not a multiple of 3");
            return data.indices;
        }
        const auto key = std::make_pair(meshIndex, primIndex);
        if (auto cached = document_.corners.find(key); cached != document_.corners.end()) return cached->second;
        return document_.corners.emplace(key, triangleCorners(mode, data, where)).first->second;
    }

    // Three vertex indices per triangle, as TRIANGLES: an unindexed primitive's vertices in
    // order, strips and fans unrolled.
    std::vector<std::uint32_t> triangleCorners(int mode, const gltf::PrimitiveData& data, const std::string& where) const {
        const std::vector<glm::dvec4>& positions = data.attributes.at(kPosition);
        std::vector<std::uint32_t> indices = data.indices;
        if (!data.indexed) {
            indices.resize(positions.size());
            for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = std::uint32_t(i);
        }

        std::vector<std::uint32_t> corners;  // three per triangle, as TRIANGLES
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            corners = std::move(indices);
        } else {
            for (std::size_t i = 2; i < indices.size(); ++i) {
                if (mode == TINYGLTF_MODE_TRIANGLE_FAN) corners.insert(corners.end(), {indices[0], indices[i - 1], indices[i]});
                else if (i % 2 == 0) corners.insert(corners.end(), {indices[i - 2], indices[i - 1], indices[i]});
                else corners.insert(corners.end(), {indices[i - 1], indices[i - 2], indices[i]});
            }
        }
        if (corners.size() % 3 != 0) check_.fail(where + ": " + str(corners.size()) + " indices is not a multiple of 3");
        return corners;
    }

    // The primitive's attribute `name`, checked to hold one element per vertex; null when absent.
    const std::vector<glm::dvec4>* vertexAttribute(const gltf::PrimitiveData& data, const std::string& name,
                                                   const std::string& where) const {
        const std::vector<glm::dvec4>& positions = data.attributes.at(kPosition);
        auto it = data.attributes.find(name);
        if (it == data.attributes.end()) return nullptr;
        if (it->second.size() != positions.size())
            check_.fail(where + ": " + name + " has " + str(it->second.size()) + " elements, POSITION has " + str(positions.size()));
        return &it->second;
    }

    VertexShading vertexShading(const tinygltf::Primitive& prim, const gltf::PrimitiveData& data, std::uint32_t material,
                                const std::string& where) const {
        VertexShading shading;
        shading.normals = vertexAttribute(data, kNormal, where);
        shading.colors = vertexAttribute(data, kColor, where);
        const TextureBinding& texture = scene_.materials[material].baseColorTexture;
        shading.texCoords = texture.texture >= 0 ? vertexAttribute(data, texCoordName(texture.texCoord), where) : nullptr;
        shading.colorHasAlpha = shading.colors && prim.attributes.count(kColor) &&
                                model_.accessors[std::size_t(prim.attributes.at(kColor))].type == TINYGLTF_TYPE_VEC4;
        return shading;
    }

    MorphedVertices morphedVertices(std::uint32_t node, std::uint32_t meshIndex, const tinygltf::Primitive& prim,
                                    const gltf::PrimitiveData& data, const std::vector<glm::dvec4>* normals,
                                    const std::string& where) const {
        const std::vector<glm::dvec4>& positions = data.attributes.at(kPosition);
        MorphedVertices morphed{{}, mappedArray<glm::dvec3>(normals ? positions.size() : 0)};
        std::vector<glm::dvec3>& local = morphed.positions;  // made by the first position offset
        std::vector<glm::dvec3>& localNormals = morphed.normals;
        for (std::size_t i = 0; i < localNormals.size(); ++i) localNormals[i] = glm::dvec3((*normals)[i]);
        if (!prim.targets.empty()) {
            const std::vector<double> weights =
                morphWeights(node, model_.meshes[meshIndex], prim.targets.size(), "node " + std::to_string(node) + " " + where);
            for (std::size_t t = 0; t < weights.size(); ++t) {
                if (weights[t] == 0.0) continue;
                if (const auto* d = vertexAttribute(data, "TARGET" + std::to_string(t) + ":" + kPosition, where)) {
                    if (local.empty()) {
                        local = mappedArray<glm::dvec3>(positions.size());
                        for (std::size_t i = 0; i < positions.size(); ++i) local[i] = glm::dvec3(positions[i]);
                    }
                    for (std::size_t i = 0; i < local.size(); ++i) local[i] += weights[t] * glm::dvec3((*d)[i]);
                }
                if (const auto* d = vertexAttribute(data, "TARGET" + std::to_string(t) + ":" + kNormal, where); d && normals)
                    for (std::size_t i = 0; i < localNormals.size(); ++i) localNormals[i] += weights[t] * glm::dvec3((*d)[i]);
            }
        }
        return morphed;
    }

    // Morph targets first (offsets weighted in the mesh's space), then the skin or the node.
    PlacedVertices placeVertices(std::uint32_t node, std::uint32_t meshIndex, const tinygltf::Primitive& prim,
                                 const gltf::PrimitiveData& data, const std::vector<glm::dvec4>* normals, const glm::dmat4& world,
                                 const std::string& where) {
        MorphedVertices morphed = morphedVertices(node, meshIndex, prim, data, normals, where);
        const std::vector<glm::dvec4>& own = data.attributes.at(kPosition);
        const std::size_t vertices = own.size();
        auto localAt = [&](std::size_t i) { return morphed.positions.empty() ? glm::dvec3(own[i]) : morphed.positions[i]; };
        PlacedVertices placed;
        const int skin = model_.nodes[node].skin;
        placed.skinned = skin >= 0;
        if (skin >= 0) placed.skinning = vertexSkinning(data, jointMatrices(skin, where), vertices, where);
        auto transformOf = [&](std::uint32_t vertex) -> const glm::dmat4& { return skin >= 0 ? placed.skinning[vertex] : world; };

        placed.worldPositions = mappedArray<glm::vec3>(vertices);
        // On the document's threads; the first non-finite vertex of all is reported.
        const std::size_t nonFinite = firstFailureInChunks(vertices, kChunk, &document_.threadPool(), [&](std::size_t i) {
            const glm::dvec3 local = localAt(i);
            if (!finite3(local)) return false;
            placed.worldPositions[i] = glm::vec3(transformOf(std::uint32_t(i)) * glm::dvec4(local, 1.0));
            return true;
        });
        if (nonFinite < vertices) {
            const glm::dvec3 p = localAt(nonFinite);
            check_.fail(where + ": vertex " + std::to_string(nonFinite) + " has a non-finite position (" + std::to_string(p.x) +
                        ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
        }
        placed.localNormals = std::move(morphed.normals);
        placed.nodeNormalMatrix = glm::transpose(glm::inverse(glm::dmat3(world)));
        placed.nodeMirrored = glm::determinant(glm::dmat3(world)) < 0.0;
        return placed;
    }

    // A triangle of the primitive as placed, front face counter-clockwise: glTF's mirroring
    // transform (negative determinant) turns the winding clockwise, and swapping two corners
    // keeps counter-clockwise the front. A skinned triangle mirrors with its first corner's
    // skinning. `index`: the vertices of its corners, in its corner order.
    static Triangle placedTriangle(std::size_t t, const std::vector<std::uint32_t>& corners, const PlacedVertices& placed,
                                   std::uint32_t cullBackFace, std::uint32_t (&index)[3]) {
        const bool mirrored =
            placed.skinned ? glm::determinant(glm::dmat3(placed.skinning[corners[t * 3]])) < 0.0 : placed.nodeMirrored;
        const int order[3] = {0, mirrored ? 2 : 1, mirrored ? 1 : 2};
        Triangle tri{};
        tri.cullBackFace = cullBackFace;
        glm::vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
        for (int k = 0; k < 3; ++k) {
            index[k] = corners[t * 3 + std::size_t(order[k])];
            *v[k] = placed.worldPositions[index[k]];
        }
        return tri;
    }

    // Never hit, so never traced. (A non-finite vertex gives a non-zero cross product: such a
    // triangle stays, for validateScene to refuse.)
    static bool dropped(const Triangle& tri) { return shared::triangleHasNoArea(tri.v0, tri.v1, tri.v2); }

    // A primitive's vertices and triangles are placed on the document's threads in chunks of
    // this many: each chunk's kept triangles land where the sequential order puts them.
    static constexpr std::size_t kChunk = 16384;
    static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

    // A chunk's triangles kept (with area), or the first of its corners whose index is out of range.
    struct ChunkCount {
        std::size_t kept = 0;
        std::size_t badCorner = kNone;
    };

    // The first pass over a primitive's triangles: each chunk's corners checked and its
    // triangles with area counted.
    std::vector<ChunkCount> countTriangles(const std::vector<std::uint32_t>& corners, const PlacedVertices& placed) {
        const std::size_t triangles = corners.size() / 3, vertices = placed.worldPositions.size();
        std::vector<ChunkCount> chunks((triangles + kChunk - 1) / kChunk);
        document_.threadPool().parallelFor(chunks.size(), [&](std::size_t c, unsigned) {
            std::uint32_t index[3];
            for (std::size_t t = c * kChunk; t < std::min(triangles, (c + 1) * kChunk); ++t) {
                for (std::size_t k = 0; k < 3; ++k)
                    if (corners[t * 3 + k] >= vertices) {
                        chunks[c].badCorner = t * 3 + k;
                        return;
                    }
                if (!dropped(placedTriangle(t, corners, placed, 0, index))) ++chunks[c].kept;
            }
        });
        return chunks;
    }

    // The primitive's triangles into the scene, front faces counter-clockwise, each with its
    // provenance (`primitive`, numbered within it), material and corners' attributes: counted,
    // then written in place, each chunk from its first kept triangle's place.
    void addTriangles(const TriangleSource& primitive, std::uint32_t material, const std::vector<std::uint32_t>& corners,
                      const PlacedVertices& placed, const VertexShading& shading, const std::string& where) {
        const std::vector<ChunkCount> chunks = countTriangles(corners, placed);
        std::vector<std::size_t> first(chunks.size());
        std::size_t kept = 0;
        for (std::size_t c = 0; c < chunks.size(); ++c) {
            if (const std::size_t bad = chunks[c].badCorner; bad != kNone)
                check_.fail(where + ": index " + std::to_string(corners[bad]) + " (triangle " + std::to_string(bad / 3) +
                            ") is out of range for " + str(placed.worldPositions.size()) + " vertices");
            first[c] = kept;
            kept += chunks[c].kept;
        }
        scene_.degenerateTrianglesDropped += corners.size() / 3 - kept;
        if (kept == 0) return;
        const std::size_t base = scene_.triangles.size(), triangles = corners.size() / 3;
        scene_.triangles.resize(base + kept);
        scene_.sources.resize(base + kept);
        scene_.materialOfTriangle.resize(base + kept);
        growCornerAttributes(base + kept, shading);
        const std::uint32_t cullBackFace = scene_.materials[material].doubleSided ? 0u : 1u;
        document_.threadPool().parallelFor(chunks.size(), [&](std::size_t c, unsigned) {
            std::uint32_t index[3];
            std::size_t at = base + first[c];
            for (std::size_t t = c * kChunk; t < std::min(triangles, (c + 1) * kChunk); ++t) {
                const Triangle tri = placedTriangle(t, corners, placed, cullBackFace, index);
                if (dropped(tri)) continue;
                scene_.triangles[at] = tri;
                scene_.sources[at] = TriangleSource{primitive.node, primitive.mesh, primitive.primitive, std::uint32_t(t)};
                scene_.materialOfTriangle[at] = material;
                writeCornerAttributes(at, index, placed, shading);
                ++at;
            }
        });
    }

    // Once any triangle has normals, colours or texture coordinates, every triangle has them,
    // with their defaults where its primitive lacks them: the arrays grown to `n` triangles.
    void growCornerAttributes(std::size_t n, const VertexShading& shading) {
        CornerAttributes& out = scene_.corners;
        if (shading.normals || !out.normals.empty()) fillTo(out.normals, n, glm::vec3(0.0f));
        if (shading.colors || !out.colors.empty()) fillTo(out.colors, n, glm::vec4(1.0f));
        if (shading.texCoords || !out.texCoords.empty()) fillTo(out.texCoords, n, glm::vec2(0.0f));
    }

    // Triangle `at`'s corners' normals, colours and texture coordinates (its vertices `index`),
    // those its primitive has (growCornerAttributes made room, with the defaults).
    void writeCornerAttributes(std::size_t at, const std::uint32_t (&index)[3], const PlacedVertices& placed,
                               const VertexShading& shading) {
        CornerAttributes& out = scene_.corners;
        for (int k = 0; shading.normals && k < 3; ++k) {
            const glm::dmat3 normalMatrix =
                placed.skinned ? glm::transpose(glm::inverse(glm::dmat3(placed.skinning[index[k]]))) : placed.nodeNormalMatrix;
            const glm::dvec3 n = normalMatrix * placed.localNormals[index[k]];
            const double length = glm::length(n);
            out.normals[at][std::size_t(k)] = length > 0.0 && std::isfinite(length) ? glm::vec3(n / length) : glm::vec3(0.0f);
        }
        for (int k = 0; shading.colors && k < 3; ++k) {
            glm::vec4 c((*shading.colors)[index[k]]);
            if (!shading.colorHasAlpha) c.a = 1.0f;
            out.colors[at][std::size_t(k)] = glm::clamp(c, 0.0f, 1.0f);
        }
        for (int k = 0; shading.texCoords && k < 3; ++k) {
            const glm::vec2 uv((*shading.texCoords)[index[k]]);
            out.texCoords[at][std::size_t(k)] = std::isfinite(uv.x) && std::isfinite(uv.y) ? uv : glm::vec2(0.0f);
        }
    }

    void takeInventory(int sceneIndex) {
        GltfInventory& inv = scene_.inventory;
        inv.loadedScene = sceneIndex < 0 ? 0 : std::uint32_t(sceneIndex);
        auto named = [](const std::string& n) { return n.empty() ? std::string() : " '" + n + "'"; };
        for (std::size_t i = 0; i < model_.scenes.size(); ++i)
            inv.scenes.push_back(str(i) + named(model_.scenes[i].name) + ": " + str(model_.scenes[i].nodes.size()) + " root node(s)" +
                                 (int(i) == sceneIndex ? " (loaded)" : ""));
        for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
            std::string compressed, triangles;
            for (const tinygltf::Primitive& p : model_.meshes[m].primitives)
                if (gltf::usesDraco(p)) compressed = ", Draco";
            try {  // meshes no node of the loaded scene places were never checked
                triangles = str(meshTriangleCount(m)) + " triangles";
            } catch (const InputError& e) {
                triangles = "unreadable (" + std::string(e.what()) + ")";
            }
            inv.meshes.push_back(str(m) + named(model_.meshes[m].name) + ": " + str(model_.meshes[m].primitives.size()) +
                                 " primitive(s), " + triangles + compressed);
        }
        for (std::size_t m = 0; m + 1 < scene_.materials.size(); ++m) {
            const Material& mat = scene_.materials[m];
            char colour[96];
            std::snprintf(colour, sizeof colour, "base colour (%.3g, %.3g, %.3g, %.3g)", mat.baseColor.r, mat.baseColor.g,
                          mat.baseColor.b, mat.baseColor.a);
            std::string texture;
            if (mat.baseColorTexture.texture >= 0)
                texture = ", texture '" + scene_.textures[std::size_t(mat.baseColorTexture.texture)].name + "' (TEXCOORD_" +
                          str(mat.baseColorTexture.texCoord) + ")";
            inv.materials.push_back(str(m) + named(mat.name) + ": " + colour + texture +
                                    (mat.doubleSided ? ", double-sided" : ", single-sided"));
        }
        for (const Texture& t : scene_.textures)
            inv.textures.push_back("'" + t.name + "': " + std::to_string(t.width) + " x " + std::to_string(t.height));
        for (std::size_t k = 0; k < model_.skins.size(); ++k) {
            std::string users;
            for (std::size_t n = 0; n < model_.nodes.size(); ++n)
                if (model_.nodes[n].skin == int(k)) users += (users.empty() ? "" : ", ") + str(n);
            inv.skins.push_back(str(k) + named(model_.skins[k].name) + ": " + str(model_.skins[k].joints.size()) +
                                " joint(s), deforms node(s) " + (users.empty() ? std::string("none") : users));
        }
        inv.extensionsUsed = model_.extensionsUsed;
        inv.extensionsRequired = model_.extensionsRequired;
    }

    GltfDocument::Impl& document_;
    gltf::AccessorReader& reader_;
    const tinygltf::Model& model_;
    GltfLimits limits_;
    GltfSelection selection_;
    const std::function<void(double)>& onProgress_;
    GltfChecker check_;
    Scene scene_;
    std::uint32_t defaultMaterial_ = 0;
    std::uint64_t plannedTriangles_ = 0;                // before the degenerate ones are dropped
    std::uint64_t assembledTriangles_ = 0;              // of the planned, so far
    // The flattening's phases (ms; the primitives' summed), for Scene::setupPhasesMs: the pose and
    // the plan; the arrays' pages mapped; the primitives' data and corners (read on first use);
    // their vertices placed; their triangles assembled (degenerate ones dropped).
    struct PhaseTimes {
        double pose = 0.0, mapMemory = 0.0, primitives = 0.0, vertices = 0.0, triangles = 0.0;
    } phases_;
    std::vector<gltf::NodePose> pose_;                  // every node's animated properties at this instant
    std::vector<std::optional<glm::dmat4>> worlds_;     // nodeWorld's, computed on demand
    std::uint64_t unweightedVertices_ = 0;              // skinned vertices without a weight
};

std::vector<unsigned char> readWholeFile(const std::string& path, const GltfLimits& limits) {
    return readRegularInput(path, limits.maxBytes ? limits.maxBytes : physicalMemoryBytes());
}

}  // namespace

// Parses and checks the file, and reads what every frame shares.
std::unique_ptr<GltfDocument::Impl> openDocument(std::span<const unsigned char> bytes, const std::string& name,
                                                 const std::string& baseDir, bool readFiles, const GltfLimits& limits) {
    if (bytes.empty()) throw InputError(name + ": the file is empty");
    checkJsonNesting(bytes, name, limits);
    auto d = std::make_unique<GltfDocument::Impl>();
    d->name = name;
    d->limits = limits;
    checkGlbVersion(bytes, name);
    checkGlbChunks(bytes, name);
    nlohmann::json json = gltf::parseGltfJson(bytes);
    if (!json.is_discarded()) gltf::checkJsonRules(json, name);
    d->prepared = gltf::prepareForParser(bytes, std::move(json));
    d->model = parseGltf(d->prepared.bytes.empty() ? bytes : std::span<const unsigned char>(d->prepared.bytes), name, baseDir,
                         readFiles);
    d->prepared.bytes = {};  // parsed: only the rewrites are read from here on
    d->reader = std::make_unique<gltf::AccessorReader>(name, d->model, d->prepared.rewrites);
    d->reader->setByteLimit(d->memoryLimit());
    const GltfChecker check(*d->reader);
    check.checkExtensions(d->shared.warnings);
    check.checkCameras();
    d->parent = check.checkNodes(d->shared.warnings);
    gltf::decodeMeshoptViews(*d->reader);
    gltf::readMaterials(*d->reader, gltf::ImageSource{baseDir, readFiles}, d->shared);
    Material fallback;
    fallback.name = "(default)";
    d->shared.materials.push_back(fallback);
    d->animations = gltf::readAnimations(*d->reader, d->shared.warnings);
    for (const gltf::Animation& a : d->animations)
        d->animationInfo.push_back(GltfAnimationInfo{a.name, a.start, a.end, a.channels.size()});
    return d;
}

GltfDocument::GltfDocument(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GltfDocument::GltfDocument(GltfDocument&&) noexcept = default;
GltfDocument& GltfDocument::operator=(GltfDocument&&) noexcept = default;
GltfDocument::~GltfDocument() = default;

GltfDocument GltfDocument::open(const std::string& path, const GltfLimits& limits) {
    const std::vector<unsigned char> bytes = readWholeFile(path, limits);
    const std::string baseDir = std::filesystem::path(path).parent_path().string();
    return GltfDocument(openDocument(bytes, path, baseDir.empty() ? "." : baseDir, true, limits));
}

GltfDocument GltfDocument::fromMemory(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits) {
    return GltfDocument(openDocument(bytes, name, "", false, limits));
}

Scene GltfDocument::scene(const GltfSelection& selection, const std::function<void(double)>& onProgress) const {
    if (!std::isfinite(selection.time)) throw InputError(impl_->name + ": the time " + std::to_string(selection.time) + " is not finite");
    Scene scene = GltfFlattener(*impl_, selection, onProgress).run();
    const auto start = Clock::now();
    validateScene(scene, &impl_->threadPool());
    scene.setupPhasesMs.emplace_back("validate", msSince(start));
    return scene;
}

void GltfDocument::setThreads(unsigned threads) {
    if (threads == impl_->threads) return;
    impl_->threads = threads;
    impl_->pool.reset();
}

const std::vector<GltfAnimationInfo>& GltfDocument::animations() const { return impl_->animationInfo; }

void GltfDocument::checkAnimationChoice(const std::string& choice) const {
    gltf::chooseAnimation(impl_->animations, choice, *impl_->reader);
}

Scene loadGltf(const std::string& path, const GltfLimits& limits, const GltfSelection& selection) {
    return GltfDocument::open(path, limits).scene(selection);
}

Scene loadGltfFromMemory(std::span<const unsigned char> bytes, const std::string& name, const GltfLimits& limits,
                         const GltfSelection& selection) {
    return GltfDocument::fromMemory(bytes, name, limits).scene(selection);
}

void selectCamera(Scene& scene, const std::string& choice) {
    if (choice.empty()) return;
    auto describe = [&]() {
        std::string list;
        for (const SceneCamera& c : scene.cameras)
            list += (list.empty() ? "" : ", ") + std::to_string(c.cameraIndex) + (c.name.empty() ? "" : " '" + c.name + "'");
        return list.empty() ? std::string("the scene places no camera") : "the scene places " + list;
    };
    for (const SceneCamera& c : scene.cameras)
        if (!c.name.empty() && c.name == choice) {
            scene.camera = c;
            return;
        }
    if (const std::optional<int> index = indexChoice(choice))
        for (const SceneCamera& c : scene.cameras)
            if (c.cameraIndex == *index) {
                scene.camera = c;
                return;
            }
    throw InputError(scene.name + ": no camera is called or numbered '" + choice + "' (" + describe() + ")");
}

}  // namespace dacrt
