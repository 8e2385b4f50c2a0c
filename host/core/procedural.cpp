#include "core/procedural.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "core/errors.hpp"

namespace dacrt {

Mesh icosphere(const glm::vec3& centre, float radius, int subdivisions) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (glm::dvec3& p : v) p = glm::normalize(p);
    std::vector<std::uint32_t> f = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                                    11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                                    3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
        auto mid = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            auto it = midpoints.find(key);
            if (it != midpoints.end()) return it->second;
            v.push_back(glm::normalize(v[a] + v[b]));
            return midpoints[key] = std::uint32_t(v.size() - 1);
        };
        std::vector<std::uint32_t> next;
        for (std::size_t i = 0; i < f.size(); i += 3) {
            const std::uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
            const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        f = std::move(next);
    }
    Mesh m;
    m.name = "icosphere";
    for (const glm::dvec3& p : v) m.positions.push_back(glm::vec3(glm::dvec3(centre) + p * double(radius)));
    m.indices = std::move(f);
    return m;
}

Mesh torus(const glm::vec3& centre, float majorRadius, float minorRadius, int majorSegments, int minorSegments) {
    Mesh m;
    m.name = "torus";
    for (int i = 0; i < majorSegments; ++i) {
        const double u = 2.0 * M_PI * i / majorSegments;
        for (int j = 0; j < minorSegments; ++j) {
            const double w = 2.0 * M_PI * j / minorSegments;
            const double r = majorRadius + minorRadius * std::cos(w);
            m.positions.push_back(centre + glm::vec3(glm::dvec3(r * std::cos(u), minorRadius * std::sin(w), r * std::sin(u))));
        }
    }
    auto id = [&](int i, int j) {
        return std::uint32_t((i % majorSegments) * minorSegments + (j % minorSegments));
    };
    for (int i = 0; i < majorSegments; ++i)
        for (int j = 0; j < minorSegments; ++j)
            m.indices.insert(m.indices.end(), {id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    return m;
}

Mesh box(const glm::vec3& lo, const glm::vec3& hi) {
    Mesh m;
    m.name = "box";
    for (int c = 0; c < 8; ++c) m.positions.push_back({c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z});
    m.indices = {0, 2, 3, 0, 3, 1,  4, 5, 7, 4, 7, 6,  0, 1, 5, 0, 5, 4,
                 2, 6, 7, 2, 7, 3,  0, 4, 6, 0, 6, 2,  1, 3, 7, 1, 7, 5};
    return m;
}

Mesh cylinder(const glm::vec3& base, float radius, float height, int segments, int rings) {
    Mesh m;
    m.name = "cylinder";
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const double a = 2.0 * M_PI * s / segments;
            m.positions.push_back(base + glm::vec3(glm::dvec3(radius * std::cos(a), height * r / rings, radius * std::sin(a))));
        }
    const std::uint32_t bottom = std::uint32_t(m.positions.size());
    m.positions.push_back(base);
    m.positions.push_back(base + glm::vec3(0.0f, height, 0.0f));
    auto id = [&](int r, int s) { return std::uint32_t(r * segments + s % segments); };
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s)
            m.indices.insert(m.indices.end(), {id(r, s), id(r + 1, s), id(r + 1, s + 1), id(r, s), id(r + 1, s + 1), id(r, s + 1)});
    for (int s = 0; s < segments; ++s) {
        m.indices.insert(m.indices.end(), {bottom, id(0, s), id(0, s + 1)});
        m.indices.insert(m.indices.end(), {bottom + 1, id(rings, s + 1), id(rings, s)});
    }
    return m;
}

Mesh grid(const glm::vec3& corner, const glm::vec3& edgeU, const glm::vec3& edgeV, int segmentsU, int segmentsV) {
    Mesh m;
    m.name = "grid";
    for (int j = 0; j <= segmentsV; ++j)
        for (int i = 0; i <= segmentsU; ++i)
            m.positions.push_back(glm::vec3(glm::dvec3(corner) + glm::dvec3(edgeU) * (double(i) / segmentsU) +
                                            glm::dvec3(edgeV) * (double(j) / segmentsV)));
    auto id = [&](int i, int j) { return std::uint32_t(j * (segmentsU + 1) + i); };
    for (int j = 0; j < segmentsV; ++j)
        for (int i = 0; i < segmentsU; ++i)
            m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    return m;
}

Scene sceneFromMeshes(const std::vector<Mesh>& meshes, const std::string& name) {
    Scene s;
    s.name = name;
    for (std::size_t mi = 0; mi < meshes.size(); ++mi) {
        const Mesh& m = meshes[mi];
        s.materials.push_back(Material{"", m.color, m.doubleSided, {}});
        for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            Triangle tri{};
            tri.v0 = m.positions.at(m.indices[t]);
            tri.v1 = m.positions.at(m.indices[t + 1]);
            tri.v2 = m.positions.at(m.indices[t + 2]);
            tri.cullBackFace = m.doubleSided ? 0u : 1u;
            s.triangles.push_back(tri);
            s.sources.push_back(TriangleSource{std::uint32_t(mi), std::uint32_t(mi), 0, std::uint32_t(t / 3)});
            s.materialOfTriangle.push_back(std::uint32_t(mi));
        }
    }
    touchTriangles(s);
    return s;
}

namespace {

// One buffer view and one accessor over `count` elements appended to the buffer; the accessor's index.
int addAccessor(tinygltf::Model& model, tinygltf::Buffer& buffer, const void* data, std::size_t count, std::size_t elementBytes,
                int target, int componentType, int type) {
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = count * elementBytes;
    view.target = target;
    buffer.data.resize(view.byteOffset + view.byteLength);
    std::memcpy(buffer.data.data() + view.byteOffset, data, view.byteLength);
    model.bufferViews.push_back(view);
    tinygltf::Accessor accessor;
    accessor.bufferView = int(model.bufferViews.size() - 1);
    accessor.componentType = componentType;
    accessor.type = type;
    accessor.count = count;
    model.accessors.push_back(accessor);
    return int(model.accessors.size() - 1);
}

// The mesh as a node of the scene: one primitive with its own material.
void addMesh(tinygltf::Model& model, tinygltf::Buffer& buffer, tinygltf::Scene& scene, const Mesh& m) {
    glm::vec3 lo(kNoHitT), hi(-kNoHitT);
    for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const int positions = addAccessor(model, buffer, m.positions.data(), m.positions.size(), sizeof(glm::vec3),
                                      TINYGLTF_TARGET_ARRAY_BUFFER, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3);
    model.accessors[std::size_t(positions)].minValues = {lo.x, lo.y, lo.z};
    model.accessors[std::size_t(positions)].maxValues = {hi.x, hi.y, hi.z};
    const int indices = addAccessor(model, buffer, m.indices.data(), m.indices.size(), 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER,
                                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR);

    tinygltf::Material mat;
    mat.name = m.name;
    mat.pbrMetallicRoughness.baseColorFactor = {m.color.r, m.color.g, m.color.b, m.color.a};
    mat.doubleSided = m.doubleSided;
    model.materials.push_back(mat);
    tinygltf::Primitive prim;
    prim.attributes["POSITION"] = positions;
    prim.indices = indices;
    prim.material = int(model.materials.size() - 1);
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = m.name;
    mesh.primitives.push_back(prim);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = m.name;
    node.mesh = int(model.meshes.size() - 1);
    model.nodes.push_back(node);
    scene.nodes.push_back(int(model.nodes.size() - 1));
}

// The camera as the scene's camera 0, on a node of its own.
void addCamera(tinygltf::Model& model, tinygltf::Scene& scene, const SceneCamera& camera) {
    tinygltf::Camera cam;
    cam.type = "perspective";
    cam.perspective.yfov = camera.yfovRadians;
    cam.perspective.znear = 0.01;
    model.cameras.push_back(cam);
    // The camera node's rotation maps the glTF camera frame (-z forward, +y up) onto ours.
    const glm::dvec3 back = -glm::normalize(camera.forward);
    const glm::dvec3 right = glm::normalize(glm::cross(camera.up, back));
    const glm::dvec3 up = glm::cross(back, right);
    const glm::dquat q = glm::quat_cast(glm::dmat3(right, up, back));
    tinygltf::Node node;
    node.name = "camera";
    node.camera = 0;
    node.translation = {camera.eye.x, camera.eye.y, camera.eye.z};
    node.rotation = {q.x, q.y, q.z, q.w};
    model.nodes.push_back(node);
    scene.nodes.push_back(int(model.nodes.size() - 1));
}

}  // namespace

void writeGltf(const std::string& path, const std::vector<Mesh>& meshes, const std::optional<SceneCamera>& camera) {
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "dacrt";
    tinygltf::Buffer buffer;
    tinygltf::Scene scene;
    for (const Mesh& m : meshes) addMesh(model, buffer, scene, m);
    if (camera) addCamera(model, scene, *camera);
    model.buffers.push_back(buffer);
    model.scenes.push_back(scene);
    model.defaultScene = 0;
    const bool binary = path.size() >= 4 && path.substr(path.size() - 4) == ".glb";
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&model, path, true, true, !binary, binary))
        throw InputError(path + ": could not write the glTF file");
}

}  // namespace dacrt
