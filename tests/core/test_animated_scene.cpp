// The shipped animated scene, scenes/animated.glb (written by scenes/make_animated_scene.cpp),
// through the loader: it holds what its README says, and each object moves as its keys say at
// the keys' own times. The keys are read from the file itself (its JSON and binary chunks), so
// the tests check the scene against its data, not against a copy of the generator's constants.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/gltf_loader.hpp"

using namespace dacrt;
using nlohmann::json;

namespace {

const std::string kScene = std::string(DACRT_TEST_SCENES) + "/../../scenes/animated.glb";

// The .glb's two chunks: the JSON document and the binary buffer.
struct Glb {
    json document;
    std::vector<unsigned char> bin;

    static Glb read(const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        auto word = [&](std::size_t at) {
            std::uint32_t w = 0;
            if (at + 4 <= bytes.size()) std::memcpy(&w, bytes.data() + at, 4);
            return w;
        };
        Glb glb;
        if (bytes.size() < 20 || std::memcmp(bytes.data(), "glTF", 4) != 0 || word(4) != 2) {
            ADD_FAILURE() << path << " is not a glTF 2.0 binary file";
            return glb;
        }
        const std::size_t jsonLength = word(12);
        glb.document = json::parse(bytes.begin() + 20, bytes.begin() + 20 + std::ptrdiff_t(jsonLength));
        const std::size_t binAt = 20 + jsonLength;
        const std::size_t binLength = word(binAt);
        glb.bin.assign(bytes.begin() + std::ptrdiff_t(binAt + 8),
                       bytes.begin() + std::ptrdiff_t(binAt + 8 + binLength));
        return glb;
    }

    // A tightly packed float accessor's numbers (every float accessor the generator writes).
    std::vector<float> floats(int accessorIndex) const {
        const json& accessor = document["accessors"][std::size_t(accessorIndex)];
        EXPECT_EQ(accessor["componentType"], 5126);
        const json& view = document["bufferViews"][accessor["bufferView"].get<std::size_t>()];
        const std::size_t at = view.value("byteOffset", std::size_t(0)) + accessor.value("byteOffset", std::size_t(0));
        static const std::map<std::string, std::size_t> widths = {
            {"SCALAR", 1}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
        std::vector<float> out(accessor["count"].get<std::size_t>() * widths.at(accessor["type"]));
        EXPECT_LE(at + out.size() * 4, bin.size());
        if (at + out.size() * 4 <= bin.size()) std::memcpy(out.data(), bin.data() + at, out.size() * 4);
        return out;
    }

    int node(const std::string& name) const {
        const json& nodes = document["nodes"];
        for (std::size_t i = 0; i < nodes.size(); ++i)
            if (nodes[i].value("name", "") == name) return int(i);
        ADD_FAILURE() << "the scene has no node named '" << name << "'";
        return -1;
    }

    const json& animation(const std::string& name) const {
        for (const json& a : document["animations"])
            if (a.value("name", "") == name) return a;
        ADD_FAILURE() << "the scene has no animation named '" << name << "'";
        static const json none = {{"channels", json::array()}, {"samplers", json::array()}};
        return none;
    }

    // The sampler of the animation's channel that drives `path` of `node`.
    const json& sampler(const std::string& animationName, int node, const std::string& path) const {
        const json& a = animation(animationName);
        for (const json& channel : a["channels"])
            if (channel["target"].value("node", -1) == node && channel["target"]["path"] == path)
                return a["samplers"][channel["sampler"].get<std::size_t>()];
        ADD_FAILURE() << "animation '" << animationName << "' does not animate the " << path << " of node " << node;
        static const json none = {{"input", -1}, {"output", -1}, {"interpolation", ""}};
        return none;
    }
};

const Glb& shipped() {
    static const Glb glb = Glb::read(kScene);
    return glb;
}

Scene sceneAt(const GltfDocument& doc, double time, const std::string& animation = "") {
    return doc.scene(GltfSelection{.scene = "", .animation = animation, .time = time});
}

// The corners of the node's triangles, in the scene's order.
std::vector<glm::vec3> cornersOf(const Scene& scene, int node) {
    std::vector<glm::vec3> out;
    for (std::size_t i = 0; i < scene.triangles.size(); ++i)
        if (int(scene.sources[i].node) == node)
            out.insert(out.end(), {scene.triangles[i].v0, scene.triangles[i].v1, scene.triangles[i].v2});
    return out;
}

Box boundsOf(const Scene& scene, int node) {
    Box box;
    for (const glm::vec3& p : cornersOf(scene, node)) box.extend(p);
    return box;
}

// How far the node's furthest corner moved between two scenes of the same triangles.
double largestMove(const Scene& a, const Scene& b, int node) {
    const std::vector<glm::vec3> from = cornersOf(a, node), to = cornersOf(b, node);
    EXPECT_EQ(from.size(), to.size());
    double most = 0.0;
    for (std::size_t i = 0; i < std::min(from.size(), to.size()); ++i)
        most = std::max(most, double(glm::length(to[i] - from[i])));
    return most;
}

}  // namespace

TEST(AnimatedScene, HoldsTwoAnimationsOneSkinAndItsObjects) {
    const GltfDocument doc = GltfDocument::open(kScene);
    const std::vector<GltfAnimationInfo>& animations = doc.animations();
    ASSERT_EQ(animations.size(), 2u);
    EXPECT_EQ(animations[0].name, "sway");
    EXPECT_EQ(animations[1].name, "bounce");
    for (const GltfAnimationInfo& a : animations) {
        EXPECT_EQ(a.start, 0.0) << a.name;
        EXPECT_EQ(a.end, 2.0) << a.name;
    }
    EXPECT_EQ(animations[0].channels, 5u);  // four joints' rotations and the blob's weights
    EXPECT_EQ(animations[1].channels, 2u);  // the bouncer's translation and rotation

    const Glb& glb = shipped();
    const json& gltf = glb.document;
    ASSERT_EQ(gltf["skins"].size(), 1u);
    const json& skin = gltf["skins"][0];
    ASSERT_EQ(skin["joints"].size(), 4u);
    EXPECT_EQ(glb.floats(skin["inverseBindMatrices"].get<int>()).size(), 4u * 16u);
    EXPECT_EQ(gltf["nodes"][std::size_t(glb.node("tentacle"))]["skin"], 0);
    for (int j = 0; j < 4; ++j) {
        EXPECT_EQ(skin["joints"][std::size_t(j)], glb.node("tentacle joint " + std::to_string(j)));
        EXPECT_EQ(glb.sampler("sway", glb.node("tentacle joint " + std::to_string(j)), "rotation")["interpolation"],
                  "LINEAR");
    }
    EXPECT_EQ(glb.sampler("sway", glb.node("blob"), "weights")["interpolation"], "STEP");
    EXPECT_EQ(glb.sampler("bounce", glb.node("bouncer"), "translation")["interpolation"], "CUBICSPLINE");
    EXPECT_EQ(glb.sampler("bounce", glb.node("bouncer"), "rotation")["interpolation"], "LINEAR");
    const json& blobMesh = gltf["meshes"][gltf["nodes"][std::size_t(glb.node("blob"))]["mesh"].get<std::size_t>()];
    ASSERT_EQ(blobMesh["primitives"][0]["targets"].size(), 1u);
    EXPECT_TRUE(blobMesh["primitives"][0]["targets"][0].contains("POSITION"));
    EXPECT_TRUE(blobMesh["primitives"][0]["targets"][0].contains("NORMAL"));
    EXPECT_NE(std::find(gltf["extensionsUsed"].begin(), gltf["extensionsUsed"].end(), "KHR_lights_punctual"),
              gltf["extensionsUsed"].end());

    const Scene scene = sceneAt(doc, 0.0);
    EXPECT_TRUE(scene.warnings.empty()) << testing::PrintToString(scene.warnings);
    ASSERT_TRUE(scene.camera);
    EXPECT_EQ(scene.camera->name, "camera");
    ASSERT_EQ(scene.lights.size(), 1u);
    EXPECT_EQ(scene.lights[0].type, LightType::Point);
    EXPECT_EQ(scene.corners.normals.size(), scene.triangles.size());  // every mesh has NORMAL
    std::map<int, std::size_t> trianglesOfNode;
    for (const TriangleSource& s : scene.sources) ++trianglesOfNode[int(s.node)];
    for (const char* name : {"floor", "back wall", "tentacle", "bouncer", "blob"})
        EXPECT_GT(trianglesOfNode[glb.node(name)], 500u) << name;
    EXPECT_EQ(trianglesOfNode.size(), 5u);
    EXPECT_LT(scene.triangles.size(), 20000u);  // small enough for quick tests at small sizes
    std::set<std::uint32_t> materials(scene.materialOfTriangle.begin(), scene.materialOfTriangle.end());
    EXPECT_EQ(materials.size(), 5u);  // each object its own colour
}

// Every triangle survives every pose (none collapses to no area), and its shading normals stay on
// its front side: the animated meshes keep their winding and their normals together.
TEST(AnimatedScene, KeepsEveryTriangleAndItsFrontAtEveryTime) {
    const GltfDocument doc = GltfDocument::open(kScene);
    const Scene rest = sceneAt(doc, 0.0);
    for (const std::string animation : {"", "sway", "bounce"})
        for (int step = 0; step <= 20; ++step) {
            const double t = 0.125 * step - 0.25;  // from before the first key to past the last
            const Scene s = sceneAt(doc, t, animation);
            SCOPED_TRACE("animation '" + animation + "' at " + std::to_string(t) + " s");
            ASSERT_EQ(s.triangles.size(), rest.triangles.size());
            EXPECT_EQ(s.degenerateTrianglesDropped, 0u);
            std::size_t backwards = 0, sameSource = 0;
            for (std::size_t i = 0; i < s.triangles.size(); ++i) {
                const std::array<glm::vec3, 3>& n = s.corners.normals[i];
                backwards += glm::dot(geometricNormal(s.triangles[i]), n[0] + n[1] + n[2]) <= 0.0f;
                sameSource +=
                    s.sources[i].node == rest.sources[i].node && s.sources[i].triangle == rest.sources[i].triangle;
            }
            EXPECT_EQ(backwards, 0u);
            EXPECT_EQ(sameSource, s.triangles.size());
        }
}

TEST(AnimatedScene, SkinnedTentacleBendsWhileTheFloorStays) {
    const GltfDocument doc = GltfDocument::open(kScene);
    const Glb& glb = shipped();
    const int tentacle = glb.node("tentacle"), floor = glb.node("floor");
    const Scene start = sceneAt(doc, 0.0, "sway"), later = sceneAt(doc, 0.75, "sway");
    EXPECT_GT(largestMove(start, later, tentacle), 0.5);  // its tip sways by about a metre
    EXPECT_EQ(largestMove(start, later, floor), 0.0);
    // A bend, not a shift: the base stays on the floor while the tip swings.
    const Box a = boundsOf(start, tentacle), b = boundsOf(later, tentacle);
    EXPECT_NEAR(a.lo.y, 0.0, 0.05);
    EXPECT_NEAR(b.lo.y, 0.0, 0.05);
    EXPECT_GT(std::abs(b.center().x - a.center().x), 0.3f);
    // "bounce" alone leaves the tentacle in its rest pose at every time.
    EXPECT_EQ(largestMove(sceneAt(doc, 0.0, "bounce"), sceneAt(doc, 0.75, "bounce"), tentacle), 0.0);
}

// At each key time the torus sits where its CUBICSPLINE key puts it (it is symmetric about its
// centre, so its bounds' centre is its node's translation), touching the floor at the bounces;
// between keys it follows the Hermite curve the keys' tangents make.
TEST(AnimatedScene, BouncerFollowsItsTranslationKeys) {
    const GltfDocument doc = GltfDocument::open(kScene);
    const Glb& glb = shipped();
    const int bouncer = glb.node("bouncer");
    const json& sampler = glb.sampler("bounce", bouncer, "translation");
    const std::vector<float> times = glb.floats(sampler["input"].get<int>()),
                             keys = glb.floats(sampler["output"].get<int>());
    ASSERT_EQ(keys.size(), times.size() * 9);  // in-tangent, value, out-tangent per key
    // Part 0: the in-tangent, 1: the value, 2: the out-tangent of key k.
    auto key = [&](std::size_t k, std::size_t part) {
        const float* v = &keys[k * 9 + part * 3];
        return glm::dvec3(v[0], v[1], v[2]);
    };
    std::size_t floorContacts = 0;
    for (std::size_t k = 0; k < times.size(); ++k) {
        const Box box = boundsOf(sceneAt(doc, times[k], "bounce"), bouncer);
        const glm::dvec3 value = key(k, 1);
        SCOPED_TRACE("key " + std::to_string(k) + " at " + std::to_string(times[k]) + " s");
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(box.center()[c], value[c], 1e-4);
        floorContacts += std::abs(box.lo.y) < 1e-4;
    }
    EXPECT_EQ(floorContacts, 3u);  // the start, the bounce between the hops, the end
    for (std::size_t k = 0; k + 1 < times.size(); ++k) {
        const double dt = times[k + 1] - times[k], s = 0.5;
        const glm::dvec3 hermite =
            (2 * s * s * s - 3 * s * s + 1) * key(k, 1) + (s * s * s - 2 * s * s + s) * dt * key(k, 2) +
            (-2 * s * s * s + 3 * s * s) * key(k + 1, 1) + (s * s * s - s * s) * dt * key(k + 1, 0);
        const Box box = boundsOf(sceneAt(doc, times[k] + s * dt, "bounce"), bouncer);
        EXPECT_NEAR(box.center().y, hermite.y, 1e-4) << "halfway between keys " << k << " and " << k + 1;
        // A thrown body: halfway up it is above the straight line between floor and top.
        EXPECT_GT(box.center().y, 0.5 * (key(k, 1).y + key(k + 1, 1).y) + 0.1);
    }
    // Its spin turns it: a quarter turn later its footprint is another shape.
    const Box facing = boundsOf(sceneAt(doc, 0.0, "bounce"), bouncer),
              turned = boundsOf(sceneAt(doc, 0.5, "bounce"), bouncer);
    EXPECT_GT(facing.extent().x, 2.0f * turned.extent().x);
    EXPECT_GT(turned.extent().z, 2.0f * facing.extent().z);
}

// The blob's weight is a STEP key: it holds until the next key's time, then jumps.
TEST(AnimatedScene, BlobSwellsExactlyAtItsStepKey) {
    const GltfDocument doc = GltfDocument::open(kScene);
    const Glb& glb = shipped();
    const int blob = glb.node("blob");
    const json& sampler = glb.sampler("sway", blob, "weights");
    const std::vector<float> times = glb.floats(sampler["input"].get<int>()),
                             weights = glb.floats(sampler["output"].get<int>());
    ASSERT_EQ(times.size(), weights.size());
    ASSERT_GE(times.size(), 2u);
    ASSERT_EQ(weights[0], 0.0f);
    ASSERT_GT(weights[1], 0.5f);
    const double key = times[1];
    const Scene rest = sceneAt(doc, 0.0, "sway");
    const Scene before = sceneAt(doc, key - 1e-6, "sway"), at = sceneAt(doc, key, "sway");
    const Scene held = sceneAt(doc, 0.5 * (times[1] + times[2]), "sway");
    EXPECT_EQ(largestMove(rest, before, blob), 0.0);
    EXPECT_GT(largestMove(before, at, blob), 0.2);
    EXPECT_EQ(largestMove(at, held, blob), 0.0);
    const Box small = boundsOf(before, blob), swollen = boundsOf(at, blob);
    for (int c = 0; c < 3; ++c) EXPECT_GT(swollen.extent()[c], small.extent()[c] + 0.4f);
    EXPECT_LT(glm::length(swollen.center() - small.center()), 1e-4f);  // it swells in place
}
