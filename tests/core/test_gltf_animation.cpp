// glTF animation on the host: each interpolation mode's samples against values computed by hand,
// node animation, morph targets and skins through the loader against hand-computed poses, and
// the files it must refuse. The documents are built here, as JSON with a data-URI buffer.
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/gltf_document.hpp"
#include "core/errors.hpp"
#include "core/gltf_animation.hpp"
#include "core/gltf_loader.hpp"

using namespace dacrt;
using nlohmann::json;

namespace {

using dacrt::test::Document;

// A document with one triangle, (0,0,0) (1,0,0) (0,1,0) unless given, placed by node 0.
Document triangleDocument(const std::vector<float>& corners = {0, 0, 0, 1, 0, 0, 0, 1, 0}) {
    Document d;
    const int position = d.floats(corners, "VEC3");
    d["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", position}}}}}}}};
    d["nodes"] = {{{"mesh", 0}}};
    d["scenes"] = {{{"nodes", {0}}}};
    return d;
}

// One channel's animation: keys at `times`, `values` as the path needs them.
void animate(Document& d, const std::string& name, int node, const std::string& path, const std::string& interpolation,
             const std::vector<float>& times, const std::vector<float>& values) {
    const int input = d.floats(times, "SCALAR");
    const std::string type = path == "rotation" ? "VEC4" : path == "weights" ? "SCALAR" : "VEC3";
    const int output = d.floats(values, type);
    if (!d["animations"].is_array()) d["animations"] = json::array();
    d["animations"].push_back({{"name", name},
                               {"samplers", {{{"input", input}, {"output", output}, {"interpolation", interpolation}}}},
                               {"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", path}}}}}}});
}

Scene sceneAt(const json& doc, double time, const std::string& animation = "") {
    const std::string text = doc.dump();
    return GltfDocument::fromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "anim.gltf")
        .scene(GltfSelection{.scene = "", .animation = animation, .time = time});
}

std::string refusal(const json& doc) {
    try {
        sceneAt(doc, 0.0);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

void expectVertex(const glm::vec3& v, double x, double y, double z, double tolerance = 0.0) {
    EXPECT_NEAR(v.x, x, tolerance) << "x";
    EXPECT_NEAR(v.y, y, tolerance) << "y";
    EXPECT_NEAR(v.z, z, tolerance) << "z";
}

gltf::AnimationSampler sampler(gltf::Interpolation mode, std::vector<double> times, std::vector<double> values, std::size_t width) {
    return gltf::AnimationSampler{std::move(times), std::move(values), width, mode};
}

}  // namespace

// ---- the samplers, by hand ------------------------------------------------------------------

TEST(GltfAnimation, StepHoldsEachKeyUntilTheNextAndClampsOutsideTheKeys) {
    const auto s = sampler(gltf::Interpolation::Step, {0, 1, 2}, {0, 10, 20}, 1);
    EXPECT_EQ(gltf::sampleAt(s, -1.0, false)[0], 0.0);
    EXPECT_EQ(gltf::sampleAt(s, 0.5, false)[0], 0.0);
    EXPECT_EQ(gltf::sampleAt(s, 0.999, false)[0], 0.0);
    EXPECT_EQ(gltf::sampleAt(s, 1.0, false)[0], 10.0);
    EXPECT_EQ(gltf::sampleAt(s, 1.999, false)[0], 10.0);
    EXPECT_EQ(gltf::sampleAt(s, 2.0, false)[0], 20.0);
    EXPECT_EQ(gltf::sampleAt(s, 7.0, false)[0], 20.0);
}

TEST(GltfAnimation, LinearInterpolatesEachComponent) {
    const auto s = sampler(gltf::Interpolation::Linear, {0, 1, 3}, {0, 0, 0, 4, -8, 2, 4, 0, 6}, 3);
    const std::vector<double> quarter = gltf::sampleAt(s, 0.25, false), later = gltf::sampleAt(s, 2.0, false);
    EXPECT_EQ(quarter, (std::vector<double>{1, -2, 0.5}));
    EXPECT_EQ(later, (std::vector<double>{4, -4, 4}));
    EXPECT_EQ(gltf::sampleAt(s, 3.0, false), (std::vector<double>{4, 0, 6}));
}

TEST(GltfAnimation, LinearRotationsSlerpAlongTheShorterArc) {
    // 0 to 90 degrees about z: halfway is 45 degrees (linear interpolation of the quaternions
    // would give the same direction here, so a third of the way is checked too: 30 degrees).
    const double s45 = std::sin(M_PI / 4), c45 = std::cos(M_PI / 4);
    const auto s = sampler(gltf::Interpolation::Linear, {0, 1}, {0, 0, 0, 1, 0, 0, s45, c45}, 4);
    std::vector<double> q = gltf::sampleAt(s, 1.0 / 3.0, true);
    EXPECT_NEAR(q[2], std::sin(M_PI / 12), 1e-15);
    EXPECT_NEAR(q[3], std::cos(M_PI / 12), 1e-15);
    // The same end rotation given as its negative quaternion: the same path, not the long way.
    const auto flipped = sampler(gltf::Interpolation::Linear, {0, 1}, {0, 0, 0, 1, 0, 0, -s45, -c45}, 4);
    q = gltf::sampleAt(flipped, 1.0 / 3.0, true);
    EXPECT_NEAR(std::abs(q[2]), std::sin(M_PI / 12), 1e-15);
    EXPECT_NEAR(std::abs(q[3]), std::cos(M_PI / 12), 1e-15);
    EXPECT_GT(q[2] * q[3], 0.0);
    // Nearly equal rotations: the result is still a unit quaternion.
    const auto close = sampler(gltf::Interpolation::Linear, {0, 1}, {0, 0, 0, 1, 0, 0, 1e-4, 1}, 4);
    q = gltf::sampleAt(close, 0.5, true);
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-15);
}

TEST(GltfAnimation, CubicSplineIsTheHermiteCurveWithTangentsScaledByTheInterval) {
    // Keys at 0 and 2 s: value 1, out-tangent 3; in-tangent -1, value 5. At s = 1/2 (t = 1):
    // 0.5 * 1 + 0.125 * 2 * 3 + 0.5 * 5 - 0.125 * 2 * (-1) = 4. At s = 1/4 (t = 0.5):
    // h = (0.84375, 0.140625, 0.15625, -0.046875): 0.84375 + 0.84375 + 0.78125 + 0.09375 = 2.5625.
    const auto s = sampler(gltf::Interpolation::CubicSpline, {0, 2}, {/*key 0*/ 7, 1, 3, /*key 1*/ -1, 5, 9}, 1);
    EXPECT_EQ(gltf::sampleAt(s, 1.0, false)[0], 4.0);
    EXPECT_EQ(gltf::sampleAt(s, 0.5, false)[0], 2.5625);
    // At the keys, their values; the tangents outside the range play no part.
    EXPECT_EQ(gltf::sampleAt(s, 0.0, false)[0], 1.0);
    EXPECT_EQ(gltf::sampleAt(s, 2.0, false)[0], 5.0);
    EXPECT_EQ(gltf::sampleAt(s, -3.0, false)[0], 1.0);
}

// ---- through the loader ---------------------------------------------------------------------

TEST(GltfAnimation, NodeTranslationRotationAndScaleMoveTheTriangle) {
    Document d = triangleDocument();
    animate(d, "move", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0, 2, 0, 0});
    const json doc = d.finish();
    expectVertex(sceneAt(doc, 0.25).triangles[0].v0, 0.5, 0, 0);
    expectVertex(sceneAt(doc, 0.25).triangles[0].v1, 1.5, 0, 0);
    expectVertex(sceneAt(doc, 5.0).triangles[0].v0, 2, 0, 0);

    Document r = triangleDocument();
    const float s45 = float(std::sin(M_PI / 4)), c45 = float(std::cos(M_PI / 4));
    animate(r, "turn", 0, "rotation", "STEP", {0, 1}, {0, 0, 0, 1, 0, 0, s45, c45});
    expectVertex(sceneAt(r.finish(), 0.5).triangles[0].v1, 1, 0, 0);
    expectVertex(sceneAt(r.finish(), 1.0).triangles[0].v1, 0, 1, 0, 1e-7);  // (1,0,0) turned 90 degrees about z

    Document g = triangleDocument();
    // Scale from 1 to 3 with zero tangents: at the midpoint 2 (the Hermite curve's symmetry).
    animate(g, "grow", 0, "scale", "CUBICSPLINE", {0, 1}, {0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 3, 3, 3, 0, 0, 0});
    expectVertex(sceneAt(g.finish(), 0.5).triangles[0].v1, 2, 0, 0);
}

TEST(GltfAnimation, AnAnimatedParentCarriesItsChildren) {
    Document d = triangleDocument();
    d["nodes"] = {{{"children", {1}}, {"translation", {0, 0, 0}}}, {{"mesh", 0}, {"translation", {0, 0, -1}}}};
    animate(d, "carry", 0, "translation", "LINEAR", {0, 2}, {0, 0, 0, 0, 4, 0});
    expectVertex(sceneAt(d.finish(), 1.0).triangles[0].v0, 0, 2, -1);
}

TEST(GltfAnimation, EveryAnimationPlaysTogetherUnlessOneIsChosen) {
    Document d = triangleDocument();
    animate(d, "right", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0});
    animate(d, "up", 0, "scale", "LINEAR", {0, 1}, {1, 1, 1, 1, 3, 1});
    const json doc = d.finish();
    expectVertex(sceneAt(doc, 1.0).triangles[0].v2, 1, 3, 0);        // both
    expectVertex(sceneAt(doc, 1.0, "right").triangles[0].v2, 1, 1, 0);
    expectVertex(sceneAt(doc, 1.0, "1").triangles[0].v2, 0, 3, 0);    // by index
    try {
        sceneAt(doc, 1.0, "jump");
        FAIL() << "an animation that does not exist was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no animation is called or numbered 'jump' (the file has 0 'right', 1 'up')"),
                  std::string::npos)
            << e.what();
    }
    const std::string text = doc.dump();
    const GltfDocument file = GltfDocument::fromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "a");
    ASSERT_EQ(file.animations().size(), 2u);
    EXPECT_EQ(file.animations()[1].name, "up");
    EXPECT_EQ(file.animations()[1].end, 1.0);
    EXPECT_EQ(file.animations()[1].channels, 1u);
}

TEST(GltfAnimation, MorphTargetsAddTheirWeightedOffsets) {
    Document d = triangleDocument();
    const int offsets = d.floats({0, 0, 2, 0, 0, 0, 0, 0, 0}, "VEC3");  // the first corner rises
    d["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", offsets}}};
    d["meshes"][0]["weights"] = {0.5};
    expectVertex(sceneAt(d.finish(), 0.0).triangles[0].v0, 0, 0, 1);   // the mesh's weight
    d["nodes"][0]["weights"] = {0.25};
    expectVertex(sceneAt(d.finish(), 0.0).triangles[0].v0, 0, 0, 0.5);  // the node's wins
    animate(d, "breathe", 0, "weights", "LINEAR", {0, 1}, {0, 1});
    expectVertex(sceneAt(d.finish(), 0.75).triangles[0].v0, 0, 0, 1.5);  // the animation's wins
    expectVertex(sceneAt(d.finish(), 0.75).triangles[0].v1, 1, 0, 0);
}

// Two joints: joint 1 sits at (0, 1, 0) (its inverse bind matrix takes that away) and turns
// about z; the mesh node's own transform is ignored, as glTF says.
Document skinnedDocument(const std::vector<float>& weights) {
    Document d = triangleDocument({0, 2, 0, 1, 2, 0, 0, 3, 0});
    const int joints = d.u16({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0}, "VEC4");
    const int w = d.floats(weights, "VEC4");
    glm::mat4 inverseBind1 = glm::translate(glm::mat4(1.0f), glm::vec3(0, -1, 0));
    std::vector<float> matrices(32);
    const glm::mat4 identity(1.0f);
    std::memcpy(matrices.data(), &identity[0][0], 64);
    std::memcpy(matrices.data() + 16, &inverseBind1[0][0], 64);
    const int ibm = d.floats(matrices, "MAT4");
    d["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = joints;
    d["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = w;
    d["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", ibm}}};
    d["nodes"] = {{{"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}},
                  {{"children", {2}}},
                  {{"translation", {0, 1, 0}}}};
    d["scenes"] = {{{"nodes", {0, 1}}}};
    const float s45 = float(std::sin(M_PI / 4)), c45 = float(std::cos(M_PI / 4));
    animate(d, "bend", 2, "rotation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0, s45, c45});
    return d;
}

TEST(GltfAnimation, SkinsBlendTheirJointsMatricesByTheWeights) {
    // Every vertex on joint 1: at rest where the file puts it; at t = 1 turned 90 degrees about
    // (0, 1, 0): (0, 2, 0) -> (-1, 1, 0), (1, 2, 0) -> (-1, 2, 0), (0, 3, 0) -> (-2, 1, 0).
    const json whole = skinnedDocument({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0}).finish();
    const Scene rest = sceneAt(whole, 0.0), bent = sceneAt(whole, 1.0);
    expectVertex(rest.triangles[0].v0, 0, 2, 0, 1e-6);
    expectVertex(bent.triangles[0].v0, -1, 1, 0, 1e-6);
    expectVertex(bent.triangles[0].v1, -1, 2, 0, 1e-6);
    expectVertex(bent.triangles[0].v2, -2, 1, 0, 1e-6);
    // Half on each joint: the mean of the two poses, (0, 2, 0) and (-1, 1, 0).
    const json half = skinnedDocument({0.5f, 0.5f, 0, 0, 0.5f, 0.5f, 0, 0, 0.5f, 0.5f, 0, 0}).finish();
    expectVertex(sceneAt(half, 1.0).triangles[0].v0, -0.5, 1.5, 0, 1e-6);
    // Weights that do not sum to 1 are normalized: (2, 2) is half and half.
    const json unnormalized = skinnedDocument({2, 2, 0, 0, 2, 2, 0, 0, 2, 2, 0, 0}).finish();
    expectVertex(sceneAt(unnormalized, 1.0).triangles[0].v0, -0.5, 1.5, 0, 1e-6);
}

// ---- files it must refuse -------------------------------------------------------------------

TEST(GltfAnimation, BrokenAnimationsAreRefusedWithWhatIsWrong) {
    auto refused = [](const std::function<void(Document&)>& edit, const std::string& expected) {
        Document d = triangleDocument();
        edit(d);
        const std::string message = refusal(d.finish());
        EXPECT_NE(message.find(expected), std::string::npos) << message;
    };
    refused([](Document& d) { animate(d, "a", 0, "translation", "LINEAR", {0, 1, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0}); },
            "key times must increase strictly (key 2 at 1.000000 s follows 1.000000 s)");
    refused([](Document& d) { animate(d, "a", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0}); },
            "the output accessor has 1 elements; 2 keys need 2");
    refused([](Document& d) { animate(d, "a", 0, "translation", "CUBICSPLINE", {0, 1}, {0, 0, 0, 1, 0, 0}); },
            "2 keys need 6");
    refused([](Document& d) { animate(d, "a", 0, "translation", "SMOOTH", {0, 1}, {0, 0, 0, 1, 0, 0}); },
            "interpolation 'SMOOTH' is none of STEP, LINEAR, CUBICSPLINE");
    refused([](Document& d) { animate(d, "a", 3, "translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}); },
            "animations[0].channels[0].target.node 3 is out of range (1 node)");
    refused([](Document& d) { animate(d, "a", 0, "weights", "LINEAR", {0, 1}, {0, 1}); },
            "whose mesh has no morph targets");
    refused([](Document& d) { animate(d, "a", 0, "rotation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0, 0, 2}); },
            "rotates by a quaternion of length 2.000000, not 1");
    refused(
        [](Document& d) {
            d["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
            animate(d, "a", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0});
        },
        "which has a matrix (glTF animates translation, rotation and scale only)");
    refused([](Document& d) { animate(d, "a", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0, 1, std::nanf(""), 0}); },
            "the output has a non-finite number");
}

TEST(GltfAnimation, BrokenSkinsAreRefusedWithWhatIsWrong) {
    Document d = skinnedDocument({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0});
    d["skins"][0]["joints"] = {1, 9};
    EXPECT_NE(refusal(d.finish()).find("skins[0].joints[1] 9 is out of range (3 nodes)"), std::string::npos) << refusal(d.finish());
    Document j = skinnedDocument({0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0});  // the first vertex's weight on joint slot 2 (joint 0)
    j["skins"][0]["joints"] = {1};
    EXPECT_NE(refusal(j.finish()).find("names joint 1.000000; the skin has 1"), std::string::npos) << refusal(j.finish());
    Document n = skinnedDocument({0, -1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0});
    EXPECT_NE(refusal(n.finish()).find("vertex 0 has a negative or non-finite skin weight"), std::string::npos) << refusal(n.finish());
}

TEST(GltfAnimation, AJointAtTheEndOfADeepChainOutsideTheSceneIsPlacedWithoutRecursion) {
    // Joint 1 hangs below 200,000 nodes that no scene lists (a skin's joints need not be in the
    // scene): its world transform is the chain's, here the identity, so the rest pose holds.
    Document d = skinnedDocument({0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0});
    constexpr int kChain = 200000;
    for (int i = 0; i < kChain; ++i) d["nodes"].push_back({{"children", {i + 1 < kChain ? 3 + i + 1 : 1}}});
    d["scenes"] = {{{"nodes", {0}}}};
    d["animations"] = json::array();
    const Scene s = sceneAt(d.finish(), 0.0);
    expectVertex(s.triangles[0].v0, 0, 2, 0, 1e-6);
}

TEST(GltfAnimation, DeclaredCountsWithoutBytesAreRefusedBeforeTheyAreRead) {
    // Key times in an accessor without a view are zeros: a billion of them cannot increase.
    Document keys = triangleDocument();
    animate(keys, "a", 0, "translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0});
    json doc = keys.finish();
    doc["accessors"].push_back({{"componentType", 5126}, {"count", 1000000000}, {"type", "SCALAR"}});
    doc["animations"][0]["samplers"][0]["input"] = doc["accessors"].size() - 1;
    EXPECT_NE(refusal(doc).find("has no buffer view and 0 sparse values, so its 1000000000 key times cannot increase strictly"),
              std::string::npos)
        << refusal(doc);
    // 1,000 morph targets sharing one view-less accessor of the vertex count: each read counts
    // against the limit, which one alone would pass.
    Document morph = triangleDocument();
    json many = morph.finish();
    many["accessors"].push_back({{"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
    many["meshes"][0]["primitives"][0]["targets"] = json::array();
    for (int t = 0; t < 1000; ++t) many["meshes"][0]["primitives"][0]["targets"].push_back({{"POSITION", many["accessors"].size() - 1}});
    const std::string text = many.dump();
    GltfLimits limits;
    limits.maxBytes = 20000;  // the scene's plan and any one target fit
    try {
        loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "morph.gltf", limits);
        FAIL() << "1,000 targets were read past the limit";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("with the accessors read before it), more than the 20000-byte limit"), std::string::npos)
            << e.what();
    }
}

TEST(GltfAnimation, ATimeThatIsNotFiniteIsRefused) {
    const json doc = triangleDocument().finish();
    EXPECT_THROW(sceneAt(doc, std::nan("")), InputError);
    EXPECT_THROW(sceneAt(doc, INFINITY), InputError);
}
