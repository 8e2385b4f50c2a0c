#include "core/gltf_loader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/errors.hpp"

namespace dacrt {
namespace {

class GltfFlattener {
public:
    GltfFlattener(const std::string& path, const tinygltf::Model& model) : path_(path), model_(model) {
        scene_.name = path;
        for (const tinygltf::Material& m : model.materials) {
            Material mat;
            const std::vector<double>& f = m.pbrMetallicRoughness.baseColorFactor;
            if (f.size() == 4) mat.baseColor = glm::vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
            scene_.materials.push_back(mat);
        }
        defaultMaterial_ = std::uint32_t(scene_.materials.size());
        scene_.materials.push_back(Material{});
    }

    Scene run() {
        std::vector<int> roots;
        if (!model_.scenes.empty()) {
            int index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
            if (index >= int(model_.scenes.size())) fail("default scene " + std::to_string(index) + " does not exist");
            roots = model_.scenes[std::size_t(index)].nodes;
        } else {
            // No scene: the file's root nodes (those nobody names as a child) stand in for one.
            std::vector<bool> isChild(model_.nodes.size(), false);
            for (const tinygltf::Node& n : model_.nodes)
                for (int c : n.children)
                    if (c >= 0 && std::size_t(c) < isChild.size()) isChild[std::size_t(c)] = true;
            for (std::size_t i = 0; i < model_.nodes.size(); ++i)
                if (!isChild[i]) roots.push_back(int(i));
        }
        for (int root : roots) visit(root, glm::dmat4(1.0), 0);
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

    static glm::dmat4 localTransform(const tinygltf::Node& node) {
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

    void visit(int nodeIndex, const glm::dmat4& parent, std::size_t depth) {
        if (nodeIndex < 0 || std::size_t(nodeIndex) >= model_.nodes.size())
            fail("node " + std::to_string(nodeIndex) + " does not exist");
        if (depth > model_.nodes.size()) fail("the node hierarchy has a cycle");
        const tinygltf::Node& node = model_.nodes[std::size_t(nodeIndex)];
        const glm::dmat4 world = parent * localTransform(node);
        if (node.camera >= 0) takeCamera(node.camera, world);
        if (node.mesh >= 0) {
            if (std::size_t(node.mesh) >= model_.meshes.size())
                fail("node " + std::to_string(nodeIndex) + " names mesh " + std::to_string(node.mesh) +
                     ", which does not exist");
            const tinygltf::Mesh& mesh = model_.meshes[std::size_t(node.mesh)];
            for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
                addPrimitive(std::uint32_t(nodeIndex), std::uint32_t(node.mesh), std::uint32_t(p),
                             mesh.primitives[p], world);
        }
        for (int child : node.children) visit(child, world, depth + 1);
    }

    void takeCamera(int cameraIndex, const glm::dmat4& world) {
        if (scene_.camera || std::size_t(cameraIndex) >= model_.cameras.size()) return;
        const tinygltf::Camera& cam = model_.cameras[std::size_t(cameraIndex)];
        if (cam.type != "perspective") return;  // orthographic cameras fall back to the default view
        SceneCamera c;
        c.eye = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
        c.forward = glm::normalize(glm::dvec3(world * glm::dvec4(0, 0, -1, 0)));
        c.up = glm::normalize(glm::dvec3(world * glm::dvec4(0, 1, 0, 0)));
        c.yfovRadians = cam.perspective.yfov;
        if (!(c.yfovRadians > 0.0 && c.yfovRadians < M_PI) || !std::isfinite(c.eye.x) || !std::isfinite(c.eye.y) ||
            !std::isfinite(c.eye.z) || !std::isfinite(c.forward.x + c.forward.y + c.forward.z))
            fail("camera " + std::to_string(cameraIndex) + " is not a valid perspective camera");
        scene_.camera = c;
    }

    struct ElementView {
        const unsigned char* data = nullptr;
        std::size_t stride = 0;
        std::size_t count = 0;
        int componentType = 0;
    };

    ElementView view(int accessorIndex, int expectedType, const std::string& where) const {
        if (accessorIndex < 0 || std::size_t(accessorIndex) >= model_.accessors.size())
            fail(where + ": accessor " + std::to_string(accessorIndex) + " does not exist");
        const tinygltf::Accessor& acc = model_.accessors[std::size_t(accessorIndex)];
        if (acc.type != expectedType) fail(where + ": accessor " + std::to_string(accessorIndex) + " has the wrong type");
        if (acc.sparse.isSparse) fail(where + ": sparse accessors are not supported");
        if (acc.bufferView < 0 || std::size_t(acc.bufferView) >= model_.bufferViews.size())
            fail(where + ": accessor " + std::to_string(accessorIndex) + " has no buffer view");
        const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(acc.bufferView)];
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size())
            fail(where + ": buffer view " + std::to_string(acc.bufferView) + " names a missing buffer");
        const tinygltf::Buffer& buf = model_.buffers[std::size_t(bv.buffer)];
        const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
        const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
        if (componentSize <= 0 || components <= 0) fail(where + ": accessor has an unknown component type");
        const std::size_t elementSize = std::size_t(componentSize) * std::size_t(components);
        const std::size_t stride = bv.byteStride ? bv.byteStride : elementSize;
        const std::size_t needed = acc.count == 0 ? 0 : acc.byteOffset + (acc.count - 1) * stride + elementSize;
        if (bv.byteOffset + bv.byteLength > buf.data.size())
            fail(where + ": buffer view " + std::to_string(acc.bufferView) + " runs past the end of buffer " +
                 std::to_string(bv.buffer) + " (" + std::to_string(bv.byteOffset + bv.byteLength) + " > " +
                 std::to_string(buf.data.size()) + " bytes)");
        if (needed > bv.byteLength)
            fail(where + ": accessor " + std::to_string(accessorIndex) + " runs past the end of its buffer view (" +
                 std::to_string(needed) + " > " + std::to_string(bv.byteLength) + " bytes)");
        ElementView v;
        v.data = buf.data.data() + bv.byteOffset + acc.byteOffset;
        v.stride = stride;
        v.count = acc.count;
        v.componentType = acc.componentType;
        return v;
    }

    static const char* modeName(int mode) {
        switch (mode) {
            case TINYGLTF_MODE_POINTS: return "POINTS (0)";
            case TINYGLTF_MODE_LINE: return "LINES (1)";
            case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP (2)";
            case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP (3)";
            default: return "unknown";
        }
    }

    void addPrimitive(std::uint32_t node, std::uint32_t meshIndex, std::uint32_t primIndex,
                      const tinygltf::Primitive& prim, const glm::dmat4& world) {
        const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(primIndex);
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
            fail(where + ": primitive mode " + std::string(modeName(mode)) +
                 (mode > 6 ? " " + std::to_string(mode) : std::string()) +
                 " is not supported (only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN)");
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) fail(where + ": no POSITION attribute");
        const ElementView positions = view(pos->second, TINYGLTF_TYPE_VEC3, where + " POSITION");
        if (positions.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            fail(where + ": POSITION must be float32 (quantized positions are not supported)");

        std::vector<std::uint32_t> indices;
        if (prim.indices >= 0) {
            const ElementView iv = view(prim.indices, TINYGLTF_TYPE_SCALAR, where + " indices");
            indices.resize(iv.count);
            for (std::size_t i = 0; i < iv.count; ++i) {
                const unsigned char* p = iv.data + i * iv.stride;
                switch (iv.componentType) {
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: indices[i] = *p; break;
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t x; std::memcpy(&x, p, 2); indices[i] = x; break; }
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&indices[i], p, 4); break;
                    default: fail(where + ": indices must be unsigned 8, 16 or 32-bit integers");
                }
            }
        } else {
            indices.resize(positions.count);
            for (std::size_t i = 0; i < positions.count; ++i) indices[i] = std::uint32_t(i);
        }

        std::vector<std::uint32_t> corners;  // three per triangle, as TRIANGLES
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (indices.size() % 3 != 0)
                fail(where + ": " + std::to_string(indices.size()) + " indices is not a multiple of 3");
            corners = std::move(indices);
        } else {
            for (std::size_t i = 2; i < indices.size(); ++i) {
                if (mode == TINYGLTF_MODE_TRIANGLE_FAN) corners.insert(corners.end(), {indices[0], indices[i - 1], indices[i]});
                else if (i % 2 == 0) corners.insert(corners.end(), {indices[i - 2], indices[i - 1], indices[i]});
                else corners.insert(corners.end(), {indices[i - 1], indices[i - 2], indices[i]});
            }
        }

        std::vector<glm::vec3> world_positions(positions.count);
        for (std::size_t i = 0; i < positions.count; ++i) {
            float xyz[3];
            std::memcpy(xyz, positions.data + i * positions.stride, sizeof(xyz));
            if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
                fail(where + ": vertex " + std::to_string(i) + " has a non-finite position (" +
                     std::to_string(xyz[0]) + ", " + std::to_string(xyz[1]) + ", " + std::to_string(xyz[2]) + ")");
            world_positions[i] = glm::vec3(world * glm::dvec4(xyz[0], xyz[1], xyz[2], 1.0));
        }

        std::uint32_t material = defaultMaterial_;
        if (prim.material >= 0) {
            if (std::size_t(prim.material) >= model_.materials.size())
                fail(where + ": material " + std::to_string(prim.material) + " does not exist");
            material = std::uint32_t(prim.material);
        }

        for (std::size_t t = 0; t * 3 < corners.size(); ++t) {
            Triangle tri{};
            glm::vec3* v[3] = {&tri.v0, &tri.v1, &tri.v2};
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t index = corners[t * 3 + std::size_t(k)];
                if (index >= positions.count)
                    fail(where + ": index " + std::to_string(index) + " (triangle " + std::to_string(t) +
                         ") is out of range for " + std::to_string(positions.count) + " vertices");
                *v[k] = world_positions[index];
            }
            scene_.triangles.push_back(tri);
            scene_.sources.push_back(TriangleSource{node, meshIndex, primIndex, std::uint32_t(t)});
            scene_.materialOfTriangle.push_back(material);
        }
    }

    std::string path_;
    const tinygltf::Model& model_;
    Scene scene_;
    std::uint32_t defaultMaterial_ = 0;
};

bool looksBinary(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    return in.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
}

}  // namespace

Scene loadGltf(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": no such file");
    if (std::filesystem::file_size(path, ec) == 0) throw InputError(path + ": the file is empty");

    tinygltf::TinyGLTF reader;
    reader.SetStoreOriginalJSONForExtrasAndExtensions(false);
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        ok = looksBinary(path) ? reader.LoadBinaryFromFile(&model, &err, &warn, path)
                               : reader.LoadASCIIFromFile(&model, &err, &warn, path);
    } catch (const std::exception& e) {  // nlohmann::json throws on some malformed input
        throw InputError(path + ": not a valid glTF file (" + e.what() + ")");
    }
    if (!ok) {
        while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
        throw InputError(path + ": not a valid glTF file: " + (err.empty() ? std::string("unknown error") : err));
    }
    Scene scene = GltfFlattener(path, model).run();
    validateScene(scene);
    return scene;
}

}  // namespace dacrt
