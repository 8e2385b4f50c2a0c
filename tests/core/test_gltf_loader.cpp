// Scene input: the tiny files in tests/scenes (see make_fixtures.py for their contents).
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/procedural.hpp"
#include "support/fixtures.hpp"

using namespace dacrt;
using dacrt::test::fixture;

namespace {

std::string loadError(const std::string& name) {
    try {
        loadGltf(fixture(name));
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

void expectVertex(const glm::vec3& v, float x, float y, float z) {
    EXPECT_NEAR(v.x, x, 1e-6f);
    EXPECT_NEAR(v.y, y, 1e-6f);
    EXPECT_NEAR(v.z, z, 1e-6f);
}

}  // namespace

TEST(GltfLoader, IndexedU8WithCameraAndBaseColor) {
    const Scene s = loadGltf(fixture("quad_u8_camera.gltf"));
    ASSERT_EQ(s.triangleCount(), 2u);
    expectVertex(s.triangles[1].v0, -1, -1, 0);
    expectVertex(s.triangles[1].v1, 1, 1, 0);
    expectVertex(s.triangles[1].v2, -1, 1, 0);
    EXPECT_EQ(s.sources[1].mesh, 0u);
    EXPECT_EQ(s.sources[1].primitive, 0u);
    EXPECT_EQ(s.sources[1].triangle, 1u);
    EXPECT_EQ(s.materials[s.materialOfTriangle[0]].baseColor, glm::vec4(1.0f, 0.25f, 0.125f, 1.0f));
    ASSERT_TRUE(s.camera.has_value());
    EXPECT_DOUBLE_EQ(s.camera->yfovRadians, 0.5);
    EXPECT_NEAR(s.camera->eye.z, 4.0, 1e-12);
    EXPECT_NEAR(s.camera->forward.z, -1.0, 1e-12);
}

TEST(GltfLoader, StripU16UnderMatrixNode) {
    const Scene s = loadGltf(fixture("quad_strip_u16_matrix.gltf"));
    ASSERT_EQ(s.triangleCount(), 2u);  // strip 0 1 3 2: (0 1 3) and (3 1 2) keeping the winding
    expectVertex(s.triangles[0].v0, 9, -1, 0);
    expectVertex(s.triangles[0].v1, 11, -1, 0);
    expectVertex(s.triangles[0].v2, 9, 1, 0);
    expectVertex(s.triangles[1].v0, 9, 1, 0);
    expectVertex(s.triangles[1].v1, 11, -1, 0);
    expectVertex(s.triangles[1].v2, 11, 1, 0);
    EXPECT_FALSE(s.camera.has_value());
}

TEST(GltfLoader, NonIndexedUnderTrsHierarchy) {
    const Scene s = loadGltf(fixture("triangle_trs_hierarchy.gltf"));
    ASSERT_EQ(s.triangleCount(), 1u);
    expectVertex(s.triangles[0].v0, 7, 0, 0);
    expectVertex(s.triangles[0].v1, 7, 0, -2);
    expectVertex(s.triangles[0].v2, 7, 2, 0);
    EXPECT_EQ(s.sources[0].node, 1u);
}

TEST(GltfLoader, BinaryFanU32) {
    const Scene s = loadGltf(fixture("quad_fan_u32.glb"));
    ASSERT_EQ(s.triangleCount(), 2u);
    expectVertex(s.triangles[1].v0, -1, -1, 0);
    expectVertex(s.triangles[1].v1, 1, 1, 0);
    expectVertex(s.triangles[1].v2, -1, 1, 0);
}

TEST(GltfLoader, ZeroAreaTrianglesAreDroppedAndCounted) {
    std::vector<Mesh> meshes = {grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1, 1)};
    meshes[0].indices.insert(meshes[0].indices.end(), {0, 0, 1});  // two equal vertices
    meshes[0].positions.push_back({2, 2, 0});
    meshes[0].positions.push_back({3, 3, 0});
    meshes[0].positions.push_back({4, 4, 0});
    const std::uint32_t n = std::uint32_t(meshes[0].positions.size());
    meshes[0].indices.insert(meshes[0].indices.end(), {n - 3, n - 2, n - 1});  // collinear
    const std::string path = ::testing::TempDir() + "/degenerate.gltf";
    writeGltf(path, meshes, std::nullopt);
    const Scene s = loadGltf(path);
    EXPECT_EQ(s.triangleCount(), 2u);
    EXPECT_EQ(s.degenerateTrianglesDropped, 2u);
    // Provenance still names the triangles as the file numbers them.
    EXPECT_EQ(s.sources[1].triangle, 1u);
}

TEST(GltfLoader, ASceneOfOnlyDegenerateTrianglesIsRefusedWithTheCount) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    m.indices = {0, 1, 2, 0, 0, 1};
    const std::string path = ::testing::TempDir() + "/all_degenerate.gltf";
    writeGltf(path, {m}, std::nullopt);
    try {
        loadGltf(path);
        FAIL() << "accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("all 2 have no area"), std::string::npos) << e.what();
    }
}

struct BadFile {
    const char* file;
    const char* expected;  // part of the message
};

void PrintTo(const BadFile& f, std::ostream* os) { *os << f.file; }

class GltfLoaderRejects : public ::testing::TestWithParam<BadFile> {};

TEST_P(GltfLoaderRejects, WithAClearMessageNamingTheFile) {
    const std::string message = loadError(GetParam().file);
    EXPECT_NE(message.find(GetParam().file), std::string::npos) << message;
    EXPECT_NE(message.find(GetParam().expected), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    BadInputs, GltfLoaderRejects,
    ::testing::Values(BadFile{"bad_not_gltf.gltf", "not a valid glTF file"},
                      BadFile{"bad_truncated.glb", "not a valid glTF file"},
                      BadFile{"bad_missing_buffer.gltf", "missing.bin"},
                      BadFile{"bad_index_out_of_range.gltf", "index 7 (triangle 1) is out of range for 4 vertices"},
                      BadFile{"bad_index_count.gltf", "not a multiple of 3"},
                      BadFile{"bad_nan_position.gltf", "vertex 1 has a non-finite position"},
                      BadFile{"bad_inf_position.gltf", "vertex 1 has a non-finite position"},
                      BadFile{"bad_no_triangles.gltf", "no triangles"},
                      BadFile{"bad_points_mode.gltf", "primitive mode POINTS (0) is not supported"},
                      BadFile{"does_not_exist.gltf", "no such file"}),
    [](const ::testing::TestParamInfo<BadFile>& info) {
        std::string name = info.param.file;
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return name;
    });

TEST(GltfLoader, RejectsCoordinatesBeyondTheLimit) {
    std::vector<Mesh> meshes = {grid({0, 0, 0}, {1e10f, 0, 0}, {0, 1, 0}, 1, 1)};
    const std::string path = ::testing::TempDir() + "/huge.gltf";
    writeGltf(path, meshes, std::nullopt);
    try {
        loadGltf(path);
        FAIL() << "accepted a 1e10 coordinate";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("out-of-range vertex position"), std::string::npos) << e.what();
    }
}

