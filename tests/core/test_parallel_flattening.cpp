// The flattening on the document's threads: the same triangles, provenance, materials and
// corner attributes, bit for bit, on one thread and on two (a primitive larger than a chunk
// split between them, with degenerate triangles dropped and a mirroring node), the first bad
// index reported as in sequence, and a document evaluated at one instant after another giving
// what a fresh one gives.
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "support/gltf_document.hpp"

using namespace dacrt;
using dacrt::test::Document;

namespace {

const std::string kAnimated = std::string(DACRT_TEST_SCENES) + "/../../scenes/animated.glb";

template <typename T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expectSameScene(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    EXPECT_TRUE(sameBytes(a.triangles, b.triangles));
    EXPECT_TRUE(sameBytes(a.sources, b.sources));
    EXPECT_TRUE(sameBytes(a.materialOfTriangle, b.materialOfTriangle));
    EXPECT_TRUE(sameBytes(a.corners.normals, b.corners.normals));
    EXPECT_TRUE(sameBytes(a.corners.colors, b.corners.colors));
    EXPECT_TRUE(sameBytes(a.corners.texCoords, b.corners.texCoords));
    EXPECT_EQ(a.degenerateTrianglesDropped, b.degenerateTrianglesDropped);
}

Scene sceneAt(const GltfDocument& doc, double time) { return doc.scene(GltfSelection{.time = time}); }

GltfDocument openText(const nlohmann::json& doc) {
    const std::string text = doc.dump();
    return GltfDocument::fromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "grid.gltf");
}

constexpr int kColumns = 200, kRows = 100;  // 40,000 triangles: three chunks of the flattening
constexpr int kDegenerateEvery = 7;         // every 7th triangle collapsed to an edge

// A grid of kColumns x kRows quads in one primitive with normals and colours, every 7th
// triangle degenerate, placed by a plain node and a mirroring one; a second primitive without
// either attribute (their defaults). `badIndices`: triangles whose last corner is out of range.
nlohmann::json gridDocument(const std::vector<int>& badIndices = {}) {
    Document d;
    std::vector<float> positions, normals, colors;
    for (int y = 0; y <= kRows; ++y)
        for (int x = 0; x <= kColumns; ++x) {
            positions.insert(positions.end(), {float(x) * 0.01f, float(y) * 0.013f, float((x * y) % 5) * 0.002f});
            normals.insert(normals.end(), {0.1f * float(x % 3), 1.0f, 0.2f * float(y % 4)});
            colors.insert(colors.end(), {float(x) / kColumns, float(y) / kRows, 0.5f, 0.75f});
        }
    std::vector<std::uint16_t> indices;
    for (int y = 0; y < kRows; ++y)
        for (int x = 0; x < kColumns; ++x) {
            const auto at = [&](int dx, int dy) { return std::uint16_t((y + dy) * (kColumns + 1) + x + dx); };
            for (const std::vector<std::uint16_t>& t : {std::vector<std::uint16_t>{at(0, 0), at(1, 0), at(1, 1)},
                                                        std::vector<std::uint16_t>{at(0, 0), at(1, 1), at(0, 1)}}) {
                const bool degenerate = (indices.size() / 3) % kDegenerateEvery == 0;
                indices.insert(indices.end(), {t[0], t[1], degenerate ? t[1] : t[2]});
            }
        }
    for (const int t : badIndices) indices[std::size_t(t) * 3 + 2] = std::uint16_t(60000 + t % 1000);
    const int position = d.floats(positions, "VEC3"), normal = d.floats(normals, "VEC3"), color = d.floats(colors, "VEC4");
    const int index = d.u16(indices, "SCALAR");
    const nlohmann::json shaded = {{"attributes", {{"POSITION", position}, {"NORMAL", normal}, {"COLOR_0", color}}},
                                   {"indices", index}};
    const nlohmann::json plain = {{"attributes", {{"POSITION", position}}}, {"indices", index}};
    d["meshes"] = {{{"primitives", {shaded, plain}}}};
    d["nodes"] = {{{"mesh", 0}}, {{"mesh", 0}, {"scale", {-1.0, 1.0, 2.0}}, {"translation", {0.5, -1.0, 3.0}}}};
    d["scenes"] = {{{"nodes", {0, 1}}}};
    return d.finish();
}

TEST(ParallelFlattening, ABigPrimitiveIsTheSameOnOneThreadAndTwo) {
    GltfDocument one = openText(gridDocument()), two = openText(gridDocument());
    one.setThreads(1);
    two.setThreads(2);
    const Scene a = sceneAt(one, 0.0), b = sceneAt(two, 0.0);
    expectSameScene(a, b);
    // The sequence's order and drop: per primitive instance, triangles in increasing order, the
    // degenerate ones missing; the second primitive has the attributes' defaults.
    const std::size_t perPrimitive = std::size_t(kColumns) * kRows * 2;
    const std::size_t degenerate = (perPrimitive + kDegenerateEvery - 1) / kDegenerateEvery;
    EXPECT_EQ(a.degenerateTrianglesDropped, 4 * degenerate);
    ASSERT_EQ(a.triangles.size(), 4 * (perPrimitive - degenerate));
    ASSERT_EQ(a.corners.normals.size(), a.triangles.size());
    ASSERT_EQ(a.corners.colors.size(), a.triangles.size());
    for (std::size_t i = 1; i < a.sources.size(); ++i) {
        const TriangleSource &p = a.sources[i - 1], &s = a.sources[i];
        EXPECT_NE(s.triangle % kDegenerateEvery, 0u) << i;
        if (s.node == p.node && s.primitive == p.primitive) {
            ASSERT_LT(p.triangle, s.triangle) << i;
        }
    }
    const std::size_t plainAt = perPrimitive - degenerate;  // node 0's second primitive's first triangle
    EXPECT_EQ(a.sources[plainAt].primitive, 1u);
    EXPECT_EQ(a.corners.normals[plainAt][0], glm::vec3(0.0f));
    EXPECT_EQ(a.corners.colors[plainAt][2], glm::vec4(1.0f));
    EXPECT_NE(a.corners.colors[0][0], glm::vec4(1.0f));
}

TEST(ParallelFlattening, TheFirstOutOfRangeIndexIsReportedOnAnyThreads) {
    for (const unsigned threads : {1u, 2u}) {
        GltfDocument doc = openText(gridDocument({39000, 20001, 30000}));
        doc.setThreads(threads);
        try {
            sceneAt(doc, 0.0);
            ADD_FAILURE() << "an out-of-range index was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("index 60001 (triangle 20001) is out of range"), std::string::npos) << e.what();
        }
    }
}

TEST(ParallelFlattening, TheShippedAnimatedSceneIsTheSameOnOneThreadAndTwo) {
    GltfDocument one = GltfDocument::open(kAnimated), two = GltfDocument::open(kAnimated);
    one.setThreads(1);
    two.setThreads(2);
    for (const double time : {0.0, 0.5, 1.3}) {
        SCOPED_TRACE(time);
        expectSameScene(sceneAt(one, time), sceneAt(two, time));
    }
}

TEST(ParallelFlattening, AnInstantAfterAnotherIsWhatAFreshDocumentGives) {
    const GltfDocument reused = GltfDocument::open(kAnimated);
    for (const double time : {1.3, 0.5, 0.0, 0.5}) {
        SCOPED_TRACE(time);
        expectSameScene(sceneAt(reused, time), sceneAt(GltfDocument::open(kAnimated), time));
    }
}

}  // namespace
