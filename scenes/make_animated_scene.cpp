// Generates scenes/animated.glb, the shipped animated scene: a floor and a back wall, a skinned
// tentacle that sways on a chain of four joints, a torus that bounces and spins, and a blob
// whose morph target swells it in steps, with a camera and a point light. Two animations, both
// over 0..2 s: "sway" (the skin and the morph) and "bounce" (the torus).
// Run: build/make_animated_scene scenes/animated.glb [--detail K]
//
// The file must come out byte for byte the same on every run: the shipped copy is compared with
// a fresh one by a test. Everything is computed in a fixed order from constants, in double.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <map>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/procedural.hpp"

namespace {

using namespace dacrt;

// A triangle mesh with one unit normal per vertex (the shading normals glTF's NORMAL carries).
struct Surface {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<std::uint32_t> indices;
};

// The scene's layout (metres, y up). The tentacle's joints sit `kJointSpacing` apart up its axis.
constexpr glm::dvec3 kTentacleBase{-1.2, 0.0, -0.7};
constexpr double kTentacleHeight = 2.0;  // the tube's straight part; a rounded tip sits on top
constexpr double kTentacleRadius = 0.17;  // at the base, tapering to half at the top
constexpr int kJoints = 4;
static_assert(kJoints <= 4, "every vertex may name every joint: JOINTS_0 holds four");
constexpr double kJointSpacing = kTentacleHeight / kJoints;
constexpr glm::dvec3 kBouncerRest{1.15, 0.0, -0.2};  // its x and z; y is animated
constexpr double kTorusMajor = 0.32, kTorusMinor = 0.11;
constexpr glm::dvec3 kBlobCentre{0.1, 0.95, -1.15};
constexpr double kBlobRadius = 0.4;
constexpr double kAnimationEnd = 2.0;  // seconds; both animations loop over 0..2 s

// A flat grid from procedural.hpp with the normal of its plane (edgeU x edgeV).
Surface flatGrid(const glm::vec3& corner, const glm::vec3& edgeU, const glm::vec3& edgeV, int segmentsU,
                 int segmentsV) {
    Mesh m = grid(corner, edgeU, edgeV, segmentsU, segmentsV);
    const glm::vec3 normal = glm::vec3(glm::normalize(glm::cross(glm::dvec3(edgeU), glm::dvec3(edgeV))));
    return Surface{m.positions, std::vector<glm::vec3>(m.positions.size(), normal), m.indices};
}

// A torus about the origin standing upright: its ring in the xy plane (procedural.hpp's lies in
// xz; turned a quarter about x), so that a spin about y is seen.
Surface standingTorus(double majorRadius, double minorRadius, int majorSegments, int minorSegments) {
    Mesh m = torus(glm::vec3(0.0f), float(majorRadius), float(minorRadius), majorSegments, minorSegments);
    Surface s;
    s.indices = m.indices;
    for (const glm::vec3& p : m.positions) {
        const glm::dvec3 q(p);
        // From the tube's centre line (the point of the major circle nearest p) out to p.
        const glm::dvec3 ring = glm::normalize(glm::dvec3(q.x, 0.0, q.z)) * majorRadius;
        const glm::dvec3 n = glm::normalize(q - ring);
        // A quarter turn about x (+90 degrees): xz-plane ring to xy-plane ring.
        const auto standUp = [](const glm::dvec3& v) { return glm::vec3(glm::dvec3(v.x, -v.z, v.y)); };
        s.positions.push_back(standUp(q));
        s.normals.push_back(standUp(n));
    }
    return s;
}

// The tentacle in its bind pose, straight up from `base`: a tube tapering from `radius` to half
// of it over `height`, closed by a hemisphere on top and a disc at the bottom.
Surface taperedTube(const glm::dvec3& base, double radius, double height, int segments, int rings, int tipRings) {
    Surface s;
    const double topRadius = radius * 0.5;
    const double slope = (radius - topRadius) / height;  // the radius lost per metre climbed
    auto radiusAt = [&](double y) { return radius - slope * y; };
    auto ringVertex = [&](double y, double r, double angle, const glm::dvec3& normal) {
        s.positions.push_back(glm::vec3(base + glm::dvec3(r * std::cos(angle), y, r * std::sin(angle))));
        s.normals.push_back(glm::vec3(normal));
    };
    auto angleOf = [&](int segment) { return 2.0 * M_PI * segment / segments; };
    // The side: rings 0..rings; a cone's outward normal leans up by the taper.
    for (int r = 0; r <= rings; ++r) {
        const double y = height * r / rings;
        for (int k = 0; k < segments; ++k) {
            const double a = angleOf(k);
            ringVertex(y, radiusAt(y), a, glm::normalize(glm::dvec3(std::cos(a), slope, std::sin(a))));
        }
    }
    // The tip: latitude rings above the top ring, then the pole.
    for (int r = 1; r < tipRings; ++r) {
        const double latitude = 0.5 * M_PI * r / tipRings;
        for (int k = 0; k < segments; ++k) {
            const double a = angleOf(k);
            const glm::dvec3 n(std::cos(latitude) * std::cos(a), std::sin(latitude), std::cos(latitude) * std::sin(a));
            ringVertex(height + topRadius * n.y, topRadius * std::cos(latitude), a, n);
        }
    }
    const std::uint32_t pole = std::uint32_t(s.positions.size());
    s.positions.push_back(glm::vec3(base + glm::dvec3(0.0, height + topRadius, 0.0)));
    s.normals.push_back({0.0f, 1.0f, 0.0f});
    // The bottom disc has its own rim vertices: its normal points down, the side's outwards.
    const std::uint32_t rim = std::uint32_t(s.positions.size());
    for (int k = 0; k < segments; ++k) ringVertex(0.0, radius, angleOf(k), {0.0, -1.0, 0.0});
    const std::uint32_t bottom = std::uint32_t(s.positions.size());
    s.positions.push_back(glm::vec3(base));
    s.normals.push_back({0.0f, -1.0f, 0.0f});

    auto id = [&](int ring, int segment) { return std::uint32_t(ring * segments + segment % segments); };
    // Side and tip rings alike, counter-clockwise seen from outside.
    for (int r = 0; r < rings + tipRings - 1; ++r)
        for (int k = 0; k < segments; ++k)
            s.indices.insert(s.indices.end(),
                             {id(r, k), id(r + 1, k), id(r + 1, k + 1), id(r, k), id(r + 1, k + 1), id(r, k + 1)});
    const int last = rings + tipRings - 1;
    for (int k = 0; k < segments; ++k) {
        s.indices.insert(s.indices.end(), {id(last, k), pole, id(last, k + 1)});
        s.indices.insert(s.indices.end(), {bottom, rim + std::uint32_t(k), rim + std::uint32_t((k + 1) % segments)});
    }
    return s;
}

// A geodesic sphere: an icosahedron whose faces are cut into frequency^2 triangles each, the
// points pushed out onto the sphere. (procedural.hpp's icosphere quadruples its triangles per
// level; this one grows with frequency^2, so --detail scales it like the other meshes.)
Surface geodesicSphere(const glm::dvec3& centre, double radius, int frequency) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    const std::vector<glm::dvec3> corners = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                             {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const std::vector<std::uint32_t> faces = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,
                                              11, 10, 2, 10, 7, 6, 7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8,
                                              3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    std::vector<glm::dvec3> directions;
    auto add = [&](const glm::dvec3& p) {
        directions.push_back(glm::normalize(p));
        return std::uint32_t(directions.size() - 1);
    };
    for (const glm::dvec3& c : corners) add(c);
    // Each edge's inner points, made once (from its lower-numbered corner) and shared by both faces.
    std::vector<std::vector<std::uint32_t>> edgeStart(corners.size(), std::vector<std::uint32_t>(corners.size(), 0));
    for (std::size_t f = 0; f < faces.size(); f += 3)
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = std::min(faces[f + e], faces[f + (e + 1) % 3]);
            const std::uint32_t b = std::max(faces[f + e], faces[f + (e + 1) % 3]);
            if (edgeStart[a][b] != 0) continue;
            edgeStart[a][b] = std::uint32_t(directions.size());
            for (int k = 1; k < frequency; ++k) add(glm::mix(corners[a], corners[b], double(k) / frequency));
        }
    // The point `k` steps from corner `from` towards corner `to` (0 < k < frequency).
    auto onEdge = [&](std::uint32_t from, std::uint32_t to, int k) {
        return from < to ? edgeStart[from][to] + std::uint32_t(k - 1)
                         : edgeStart[to][from] + std::uint32_t(frequency - k - 1);
    };
    std::vector<std::uint32_t> indices;
    std::vector<std::uint32_t> point;  // this face's points, (i, j) at i * (frequency + 1) + j
    for (std::size_t f = 0; f < faces.size(); f += 3) {
        const std::uint32_t a = faces[f], b = faces[f + 1], c = faces[f + 2];
        point.assign(std::size_t(frequency + 1) * std::size_t(frequency + 1), 0);
        // Point (i, j) is a + (b - a) i / frequency + (c - a) j / frequency.
        for (int i = 0; i <= frequency; ++i)
            for (int j = 0; i + j <= frequency; ++j) {
                std::uint32_t& p = point[std::size_t(i * (frequency + 1) + j)];
                if (i == 0 && j == 0) p = a;
                else if (i == frequency) p = b;
                else if (j == frequency) p = c;
                else if (j == 0) p = onEdge(a, b, i);
                else if (i == 0) p = onEdge(a, c, j);
                else if (i + j == frequency) p = onEdge(b, c, j);
                else p = add(corners[a] + (corners[b] - corners[a]) * (double(i) / frequency) +
                             (corners[c] - corners[a]) * (double(j) / frequency));
            }
        auto at = [&](int i, int j) { return point[std::size_t(i * (frequency + 1) + j)]; };
        for (int i = 0; i < frequency; ++i)
            for (int j = 0; i + j < frequency; ++j) {
                indices.insert(indices.end(), {at(i, j), at(i + 1, j), at(i, j + 1)});
                if (i + j + 1 < frequency)
                    indices.insert(indices.end(), {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
            }
    }
    Surface s;
    s.indices = std::move(indices);
    for (const glm::dvec3& d : directions) {
        s.positions.push_back(glm::vec3(centre + d * radius));
        s.normals.push_back(glm::vec3(d));
    }
    return s;
}

// Area-weighted vertex normals of the mesh the positions make with the surface's triangles.
std::vector<glm::dvec3> averagedNormals(const std::vector<glm::dvec3>& positions,
                                        const std::vector<std::uint32_t>& indices) {
    std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < indices.size(); t += 3) {
        const glm::dvec3 &a = positions[indices[t]], &b = positions[indices[t + 1]], &c = positions[indices[t + 2]];
        const glm::dvec3 n = glm::cross(b - a, c - a);  // its length is twice the area: the weight
        for (int k = 0; k < 3; ++k) sum[indices[t + std::size_t(k)]] += n;
    }
    for (glm::dvec3& n : sum) n = glm::normalize(n);
    return sum;
}

// The blob's morph target: each vertex pushed out along its normal, furthest along the six axis
// directions, so the sphere swells into a rounded star. The offsets of positions and normals.
struct MorphTarget {
    std::vector<glm::vec3> positionOffsets;
    std::vector<glm::vec3> normalOffsets;
};
MorphTarget swelling(const Surface& sphere, const glm::dvec3& centre) {
    std::vector<glm::dvec3> swollen(sphere.positions.size());
    MorphTarget target;
    for (std::size_t i = 0; i < sphere.positions.size(); ++i) {
        const glm::dvec3 n = glm::normalize(glm::dvec3(sphere.positions[i]) - centre);
        const glm::dvec3 n2 = n * n;
        const double push = 0.08 + 0.22 * glm::dot(n2, n2);  // sum of n^4: 1 on the axes, 1/3 between them
        target.positionOffsets.push_back(glm::vec3(n * push));
        swollen[i] = glm::dvec3(sphere.positions[i]) + n * push;
    }
    const std::vector<glm::dvec3> normals = averagedNormals(swollen, sphere.indices);
    for (std::size_t i = 0; i < normals.size(); ++i)
        target.normalOffsets.push_back(glm::vec3(normals[i] - glm::dvec3(sphere.normals[i])));
    return target;
}

// Each tentacle vertex's joints and weights (up to four, summing to 1): a smooth bump per bone,
// centred on the bone's middle and reaching 1.5 bones out, so that neighbouring bones blend.
void tentacleWeights(const Surface& tube, std::vector<std::uint8_t>& joints, std::vector<float>& weights) {
    for (const glm::vec3& p : tube.positions) {
        const double height = double(p.y) - kTentacleBase.y;
        double w[kJoints];
        double total = 0.0;
        for (int j = 0; j < kJoints; ++j) {
            const double distance = std::abs(height - (j + 0.5) * kJointSpacing) / (1.5 * kJointSpacing);
            const double s = std::clamp(1.0 - distance, 0.0, 1.0);
            w[j] = s * s * (3.0 - 2.0 * s);
            total += w[j];
        }
        // The joints that pull first; the unused slots name joint 0 with no weight, as glTF asks.
        int slot = 0;
        for (int j = 0; j < kJoints; ++j)
            if (w[j] > 0.0) {
                joints.push_back(std::uint8_t(j));
                weights.push_back(float(w[j] / total));
                ++slot;
            }
        for (; slot < 4; ++slot) {
            joints.push_back(0);
            weights.push_back(0.0f);
        }
    }
}

// The tentacle's sway at time t: each joint bends about z (sideways, as the camera sees it) and
// a little about x, a wave that climbs the chain and returns to its start after 2 s.
glm::dquat jointRotation(int joint, double t) {
    static constexpr double kAmplitude[kJoints] = {0.12, 0.28, 0.34, 0.40};  // radians
    const double phase = 2.0 * M_PI * t / kAnimationEnd - 0.7 * joint;
    return glm::angleAxis(kAmplitude[joint] * std::sin(phase), glm::dvec3(0, 0, 1)) *
           glm::angleAxis(0.4 * kAmplitude[joint] * std::cos(phase), glm::dvec3(1, 0, 0));
}

// The glTF model under construction: every accessor over its own view of the one buffer.
class ModelBuilder {
public:
    ModelBuilder() {
        model_.asset.version = "2.0";
        model_.asset.generator = "dacrt make_animated_scene";
        model_.buffers.emplace_back();
    }

    int floats(std::span<const float> values, int type, int target = 0, bool withBounds = false) {
        const std::size_t width = componentsOf(type);
        const int accessor =
            add(values.data(), values.size_bytes(), values.size() / width, TINYGLTF_COMPONENT_TYPE_FLOAT, type, target);
        if (withBounds) {
            // glTF requires min and max on POSITION and on animation inputs.
            std::vector<double> lo(width, HUGE_VAL), hi(width, -HUGE_VAL);
            for (std::size_t i = 0; i < values.size(); ++i) {
                lo[i % width] = std::min(lo[i % width], double(values[i]));
                hi[i % width] = std::max(hi[i % width], double(values[i]));
            }
            model_.accessors.back().minValues = lo;
            model_.accessors.back().maxValues = hi;
        }
        return accessor;
    }
    int vec3s(const std::vector<glm::vec3>& values, bool withBounds) {
        return floats({&values[0].x, values.size() * 3}, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, withBounds);
    }
    int times(const std::vector<float>& seconds) { return floats(seconds, TINYGLTF_TYPE_SCALAR, 0, true); }
    int indices(const std::vector<std::uint32_t>& values) {
        return add(values.data(), values.size() * 4, values.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                   TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    }
    int jointIndices(const std::vector<std::uint8_t>& values) {
        return add(values.data(), values.size(), values.size() / 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                   TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    }

    int material(const std::string& name, const glm::dvec3& color) {
        tinygltf::Material m;
        m.name = name;
        m.pbrMetallicRoughness.baseColorFactor = {color.r, color.g, color.b, 1.0};
        m.pbrMetallicRoughness.metallicFactor = 0.0;
        model_.materials.push_back(m);
        return int(model_.materials.size() - 1);
    }

    // A mesh of one triangle primitive with POSITION, NORMAL and `extra` attributes.
    int mesh(const std::string& name, const Surface& s, int materialIndex,
             const std::map<std::string, int>& extra = {}) {
        tinygltf::Primitive prim;
        prim.attributes = extra;
        prim.attributes["POSITION"] = vec3s(s.positions, true);
        prim.attributes["NORMAL"] = vec3s(s.normals, false);
        prim.indices = indices(s.indices);
        prim.material = materialIndex;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Mesh m;
        m.name = name;
        m.primitives.push_back(prim);
        model_.meshes.push_back(m);
        return int(model_.meshes.size() - 1);
    }

    int node(tinygltf::Node n) {
        model_.nodes.push_back(std::move(n));
        return int(model_.nodes.size() - 1);
    }

    tinygltf::Model& model() { return model_; }

private:
    static std::size_t componentsOf(int type) {
        switch (type) {
            case TINYGLTF_TYPE_SCALAR: return 1;
            case TINYGLTF_TYPE_VEC3: return 3;
            case TINYGLTF_TYPE_VEC4: return 4;
            case TINYGLTF_TYPE_MAT4: return 16;
        }
        throw std::logic_error("make_animated_scene: an accessor type it does not write");
    }

    int add(const void* data, std::size_t bytes, std::size_t count, int componentType, int type, int target) {
        std::vector<unsigned char>& buffer = model_.buffers[0].data;
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = buffer.size();  // every element here is a multiple of 4 bytes: views stay aligned
        view.byteLength = bytes;
        view.target = target;
        buffer.resize(buffer.size() + bytes);
        std::memcpy(buffer.data() + view.byteOffset, data, bytes);
        model_.bufferViews.push_back(view);
        tinygltf::Accessor accessor;
        accessor.bufferView = int(model_.bufferViews.size() - 1);
        accessor.componentType = componentType;
        accessor.type = type;
        accessor.count = count;
        model_.accessors.push_back(accessor);
        return int(model_.accessors.size() - 1);
    }

    tinygltf::Model model_;
};

tinygltf::Node namedNode(const std::string& name) {
    tinygltf::Node n;
    n.name = name;
    return n;
}

std::vector<double> asVector(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
std::vector<double> asVector(const glm::dquat& q) { return {q.x, q.y, q.z, q.w}; }

void addChannel(tinygltf::Animation& animation, int input, int output, const std::string& interpolation, int node,
                const std::string& path) {
    tinygltf::AnimationSampler sampler;
    sampler.input = input;
    sampler.output = output;
    sampler.interpolation = interpolation;
    animation.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = int(animation.samplers.size() - 1);
    channel.target_node = node;
    channel.target_path = path;
    animation.channels.push_back(channel);
}

struct Counts {
    std::size_t triangles = 0;
    std::size_t vertices = 0;
};

Counts buildScene(ModelBuilder& b, int detail) {
    Counts counts;
    auto count = [&](const Surface& s) {
        counts.triangles += s.indices.size() / 3;
        counts.vertices += s.positions.size();
    };
    tinygltf::Scene scene;
    scene.name = "animated";

    // The stage: a floor and a back wall, static.
    const Surface floor =
        flatGrid({-4.0f, 0.0f, 2.5f}, {8.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -5.0f}, 32 * detail, 20 * detail);
    const Surface wall =
        flatGrid({-4.0f, 0.0f, -2.5f}, {8.0f, 0.0f, 0.0f}, {0.0f, 3.5f, 0.0f}, 32 * detail, 14 * detail);
    count(floor), count(wall);
    for (const auto& [name, surface, color] : {std::tuple{"floor", &floor, glm::dvec3(0.55, 0.52, 0.47)},
                                               std::tuple{"back wall", &wall, glm::dvec3(0.45, 0.55, 0.7)}}) {
        tinygltf::Node n = namedNode(name);
        n.mesh = b.mesh(name, *surface, b.material(name, color));
        scene.nodes.push_back(b.node(n));
    }

    // The tentacle: a skinned mesh (its node's own transform plays no part; the joints place it)
    // on a chain of joints kJointSpacing apart, the first at its base.
    const Surface tube =
        taperedTube(kTentacleBase, kTentacleRadius, kTentacleHeight, 32 * detail, 40 * detail, 8 * detail);
    count(tube);
    std::vector<std::uint8_t> joints;
    std::vector<float> weights;
    tentacleWeights(tube, joints, weights);
    const int jointsAccessor = b.jointIndices(joints);
    const int weightsAccessor = b.floats(weights, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    tinygltf::Node tentacle = namedNode("tentacle");
    tentacle.mesh = b.mesh("tentacle", tube, b.material("tentacle", {0.75, 0.3, 0.45}),
                           {{"JOINTS_0", jointsAccessor}, {"WEIGHTS_0", weightsAccessor}});
    tentacle.skin = 0;
    scene.nodes.push_back(b.node(tentacle));
    tinygltf::Skin skin;
    skin.name = "tentacle";
    std::vector<float> inverseBind;
    for (int j = 0; j < kJoints; ++j) {
        tinygltf::Node joint = namedNode("tentacle joint " + std::to_string(j));
        joint.translation = asVector(j == 0 ? kTentacleBase : glm::dvec3(0.0, kJointSpacing, 0.0));
        skin.joints.push_back(b.node(joint));
        if (j > 0) b.model().nodes[std::size_t(skin.joints[std::size_t(j - 1)])].children.push_back(skin.joints.back());
        // The bind pose is the mesh as stored: each joint's inverse bind matrix undoes its place.
        const glm::dmat4 bind =
            glm::translate(glm::dmat4(1.0), -(kTentacleBase + glm::dvec3(0.0, j * kJointSpacing, 0.0)));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) inverseBind.push_back(float(bind[c][r]));
    }
    skin.skeleton = skin.joints.front();
    skin.inverseBindMatrices = b.floats(inverseBind, TINYGLTF_TYPE_MAT4);
    b.model().skins.push_back(skin);
    scene.nodes.push_back(skin.joints.front());

    // The bouncer: a torus, animated rigidly by its node.
    const Surface ring = standingTorus(kTorusMajor, kTorusMinor, 48 * detail, 20 * detail);
    count(ring);
    tinygltf::Node bouncer = namedNode("bouncer");
    bouncer.mesh = b.mesh("bouncer", ring, b.material("bouncer", {0.95, 0.65, 0.15}));
    bouncer.translation = asVector(kBouncerRest + glm::dvec3(0.0, kTorusMajor + kTorusMinor, 0.0));
    const int bouncerNode = b.node(bouncer);
    scene.nodes.push_back(bouncerNode);

    // The blob: a sphere with one morph target, hovering above the floor.
    const Surface sphere = geodesicSphere(kBlobCentre, kBlobRadius, 16 * detail);
    count(sphere);
    const MorphTarget swell = swelling(sphere, kBlobCentre);
    tinygltf::Node blob = namedNode("blob");
    blob.mesh = b.mesh("blob", sphere, b.material("blob", {0.3, 0.7, 0.45}));
    {
        tinygltf::Mesh& m = b.model().meshes[std::size_t(blob.mesh)];
        m.weights = {0.0};
        m.primitives[0].targets.push_back({{"POSITION", b.vec3s(swell.positionOffsets, true)},
                                           {"NORMAL", b.vec3s(swell.normalOffsets, false)}});
    }
    const int blobNode = b.node(blob);
    scene.nodes.push_back(blobNode);

    // The camera, looking slightly down at the middle of the stage, and a point light above it.
    const glm::dvec3 eye(-0.2, 1.5, 4.0), lookAt(-0.2, 0.95, -0.8);
    const glm::dvec3 back = glm::normalize(eye - lookAt);
    const glm::dvec3 right = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), back));
    tinygltf::Camera camera;
    camera.name = "camera";
    camera.type = "perspective";
    camera.perspective.yfov = glm::radians(45.0);
    camera.perspective.znear = 0.05;
    camera.perspective.zfar = 100.0;
    b.model().cameras.push_back(camera);
    tinygltf::Node cameraNode = namedNode("camera");
    cameraNode.camera = 0;
    cameraNode.translation = asVector(eye);
    // glTF's camera looks down its -z with +y up.
    cameraNode.rotation = asVector(glm::quat_cast(glm::dmat3(right, glm::cross(back, right), back)));
    scene.nodes.push_back(b.node(cameraNode));

    tinygltf::Light lamp;
    lamp.name = "lamp";
    lamp.type = "point";
    lamp.color = {1.0, 0.95, 0.88};
    lamp.intensity = 60.0;
    b.model().lights.push_back(lamp);
    tinygltf::Node lampNode = namedNode("lamp");
    lampNode.translation = {1.6, 3.4, 2.4};
    lampNode.extensions["KHR_lights_punctual"] =
        tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(0)}});
    scene.nodes.push_back(b.node(lampNode));
    b.model().extensionsUsed.push_back("KHR_lights_punctual");

    // "sway": the joints' rotations, LINEAR keys every 1/8 s (the sway turns them by far less
    // than 180 degrees between keys), and the blob's morph weight, STEP keys every 1/2 s.
    tinygltf::Animation sway;
    sway.name = "sway";
    {
        std::vector<float> keyTimes;
        for (int k = 0; k <= 16; ++k) keyTimes.push_back(float(kAnimationEnd * k / 16));
        const int input = b.times(keyTimes);
        for (int j = 0; j < kJoints; ++j) {
            std::vector<float> rotations;
            for (float t : keyTimes)
                for (double x : asVector(jointRotation(j, t))) rotations.push_back(float(x));
            addChannel(sway, input, b.floats(rotations, TINYGLTF_TYPE_VEC4), "LINEAR", skin.joints[std::size_t(j)],
                       "rotation");
        }
        const int stepInput = b.times({0.0f, 0.5f, 1.0f, 1.5f, 2.0f});
        addChannel(sway, stepInput, b.floats(std::vector<float>{0.0f, 1.0f, 0.35f, 1.0f, 0.0f}, TINYGLTF_TYPE_SCALAR),
                   "STEP", blobNode, "weights");
    }
    b.model().animations.push_back(sway);

    // "bounce": two hops of the torus, CUBICSPLINE translation keys at the floor and the tops,
    // with the tangents of a parabola (the velocity flips at the floor: in and out tangents
    // differ there), and one full spin about y, LINEAR keys 45 degrees apart.
    tinygltf::Animation bounce;
    bounce.name = "bounce";
    {
        const double floorY = kTorusMajor + kTorusMinor;
        const double tops[2] = {1.5, 1.1};  // the torus centre's height at the top of each hop
        const double hop = 0.5;              // seconds from the floor to a top
        std::vector<float> translationKeys;
        auto key = [&](double inTangentY, double y, double outTangentY) {
            for (const glm::dvec3& v : {glm::dvec3(0.0, inTangentY, 0.0), glm::dvec3(kBouncerRest.x, y, kBouncerRest.z),
                                        glm::dvec3(0.0, outTangentY, 0.0)})
                for (double x : asVector(v)) translationKeys.push_back(float(x));
        };
        // A Hermite segment from the floor with velocity 2 rise / hop to a top with velocity 0
        // is the parabola of a thrown body.
        const double rise0 = tops[0] - floorY, rise1 = tops[1] - floorY;
        key(-2.0 * rise0 / hop, floorY, 2.0 * rise0 / hop);
        key(0.0, tops[0], 0.0);
        key(-2.0 * rise0 / hop, floorY, 2.0 * rise1 / hop);
        key(0.0, tops[1], 0.0);
        key(-2.0 * rise1 / hop, floorY, 2.0 * rise1 / hop);
        addChannel(bounce, b.times({0.0f, 0.5f, 1.0f, 1.5f, 2.0f}), b.floats(translationKeys, TINYGLTF_TYPE_VEC3),
                   "CUBICSPLINE", bouncerNode, "translation");
        std::vector<float> spinTimes, spinKeys;
        for (int k = 0; k <= 8; ++k) {
            spinTimes.push_back(float(kAnimationEnd * k / 8));
            for (double x : asVector(glm::angleAxis(2.0 * M_PI * k / 8, glm::dvec3(0, 1, 0))))
                spinKeys.push_back(float(x));
        }
        addChannel(bounce, b.times(spinTimes), b.floats(spinKeys, TINYGLTF_TYPE_VEC4), "LINEAR", bouncerNode,
                   "rotation");
    }
    b.model().animations.push_back(bounce);

    b.model().scenes.push_back(scene);
    b.model().defaultScene = 0;
    return counts;
}

// --detail's value: a whole number from 1 to kMaxDetail.
constexpr int kMaxDetail = 16;  // 16^2 times the default's triangles: about 3 million
int parseDetail(const std::string& text) {
    std::size_t used = 0;
    int value = 0;
    try {
        value = std::stoi(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != text.size() || text.empty() || value < 1 || value > kMaxDetail)
        throw std::invalid_argument("--detail wants a whole number from 1 to " + std::to_string(kMaxDetail) +
                                    ", not '" + text + "'");
    return value;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string usage =
        "usage: make_animated_scene OUT.glb [--detail K]\n"
        "  --detail K  multiply every mesh's tessellation by K (1 to " + std::to_string(kMaxDetail) +
        "; K^2 times the triangles); default 1, the shipped scenes/animated.glb\n";
    std::string out;
    int detail = 1;
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            if (arg == "-h" || arg == "--help") {
                std::cout << usage;
                return 0;
            } else if (arg == "--detail") {
                if (i + 1 >= argc) throw std::invalid_argument("--detail needs a value");
                detail = parseDetail(argv[++i]);
            } else if (arg.rfind("--detail=", 0) == 0) {
                detail = parseDetail(arg.substr(9));
            } else if (arg.rfind("-", 0) == 0) {
                throw std::invalid_argument("unknown option '" + arg + "'");
            } else if (!out.empty()) {
                throw std::invalid_argument("one output file, not both '" + out + "' and '" + arg + "'");
            } else {
                out = arg;
            }
        }
        if (out.empty()) throw std::invalid_argument("no output file");
        const bool binary = out.size() >= 4 && out.compare(out.size() - 4, 4, ".glb") == 0;
        const bool text = out.size() >= 5 && out.compare(out.size() - 5, 5, ".gltf") == 0;
        if (!binary && !text) throw std::invalid_argument("the output '" + out + "' should end in .glb (or .gltf)");

        ModelBuilder builder;
        const Counts counts = buildScene(builder, detail);
        // Serialized to memory by tinygltf, then written here: its file writer does not report a
        // failed write, and a half-written scene must never replace the shipped one.
        std::ostringstream serialized;
        tinygltf::TinyGLTF writer;
        if (!writer.WriteGltfSceneToStream(&builder.model(), serialized, !binary, binary)) {
            std::cerr << "make_animated_scene: tinygltf could not serialize the scene\n";
            return 1;
        }
        writeFileAtomically(out, serialized.str());
        std::cout << "wrote " << out << ": " << counts.triangles << " triangles, " << counts.vertices << " vertices\n";
    } catch (const std::invalid_argument& e) {
        std::cerr << "make_animated_scene: " << e.what() << "\n" << usage;
        return 2;
    } catch (const InputError& e) {
        std::cerr << "make_animated_scene: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
