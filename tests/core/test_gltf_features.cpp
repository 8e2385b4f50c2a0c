// glTF features beyond plain geometry, one test each, on the fixtures of make_fixtures.py and on
// meshopt- and Draco-compressed twins encoded here by the reference encoders.
#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <tuple>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "support/data_uri.hpp"
#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/procedural.hpp"
#include "core/shading.hpp"
#include "support/fixtures.hpp"

using namespace dacrt;
using dacrt::test::fixture;

namespace {

using dacrt::test::base64;
using dacrt::test::dataUri;

// The hit of the point p on triangle `prim` (barycentrics solved in double).
Hit hitAt(const Scene& s, std::uint32_t prim, glm::dvec3 p) {
    const Triangle& t = s.triangles[prim];
    const glm::dvec3 a(t.v0), e1 = glm::dvec3(t.v1) - a, e2 = glm::dvec3(t.v2) - a, q = p - a;
    const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    const double q1 = glm::dot(q, e1), q2 = glm::dot(q, e2), det = d11 * d22 - d12 * d12;
    Hit h{};
    h.prim = prim;
    h.t = 1.0f;
    h.u = float((d22 * q1 - d12 * q2) / det);
    h.v = float((d11 * q2 - d12 * q1) / det);
    return h;
}

// The triangle of the quad (z = 0, [-1, 1]^2) that holds (x, y).
Hit quadHit(const Scene& s, double x, double y) {
    for (std::uint32_t k = 0; k < s.triangleCount(); ++k) {
        const Hit h = hitAt(s, k, {x, y, 0.0});
        if (h.u >= 0 && h.v >= 0 && h.u + h.v <= 1) return h;
    }
    ADD_FAILURE() << "no triangle holds (" << x << ", " << y << ")";
    return Hit{};
}

void expectColor(const glm::vec3& c, float r, float g, float b) {
    EXPECT_NEAR(c.r, r, 1e-5f);
    EXPECT_NEAR(c.g, g, 1e-5f);
    EXPECT_NEAR(c.b, b, 1e-5f);
}

// Each triangle's corners rotated to start at the smallest (keeping the winding), then sorted:
// the same list for the same triangles in any order.
std::vector<std::array<float, 9>> canonical(const std::vector<Triangle>& triangles) {
    std::vector<std::array<float, 9>> out;
    for (const Triangle& t : triangles) {
        std::array<glm::vec3, 3> v{t.v0, t.v1, t.v2};
        auto less = [](const glm::vec3& a, const glm::vec3& b) {
            return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
        };
        std::rotate(v.begin(), std::min_element(v.begin(), v.end(), less), v.end());
        out.push_back({v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z});
    }
    std::sort(out.begin(), out.end());
    return out;
}


template <typename T>
std::vector<unsigned char> bytesOf(const std::vector<T>& v) {
    const auto* p = reinterpret_cast<const unsigned char*>(v.data());
    return {p, p + v.size() * sizeof(T)};
}

Scene loadJson(const nlohmann::json& doc, const std::string& name) {
    const std::string text = doc.dump();
    return loadGltfFromMemory({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, name);
}

// The loader's message for a document it must refuse; "(loaded)" when it does not.
std::string refusal(const nlohmann::json& doc, const std::string& name) {
    try {
        loadJson(doc, name);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded)";
}

// A torus as a plain glTF (positions and u32 indices in one data-URI buffer).
nlohmann::json plainDocument(const Mesh& m) {
    std::vector<unsigned char> data = bytesOf(m.positions);
    const std::vector<unsigned char> idx = bytesOf(m.indices);
    data.insert(data.end(), idx.begin(), idx.end());
    return {{"asset", {{"version", "2.0"}}},
            {"buffers", {{{"byteLength", data.size()}, {"uri", dataUri(data)}}}},
            {"bufferViews", {{{"buffer", 0}, {"byteLength", m.positions.size() * 12}},
                             {{"buffer", 0}, {"byteOffset", m.positions.size() * 12}, {"byteLength", idx.size()}}}},
            {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", m.positions.size()}, {"type", "VEC3"}},
                           {{"bufferView", 1}, {"componentType", 5125}, {"count", m.indices.size()}, {"type", "SCALAR"}}}},
            {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
            {"nodes", {{{"mesh", 0}}}},
            {"scenes", {{{"nodes", {0}}}}}};
}

Mesh testMesh() { return torus({0.2f, -0.1f, 0.3f}, 1.0f, 0.3f, 24, 12); }

}  // namespace

TEST(GltfFeatures, ATexturedQuadShowsItsTexelsThroughTexcoordAndSampler) {
    // 2x2 texture red, green / blue, white; image top-left at the quad's corner (-1, 1); NEAREST.
    for (const char* name : {"quad_texture_image.glb", "quad_texture_data_uri.gltf"}) {
        SCOPED_TRACE(name);
        const Scene s = loadGltf(fixture(name));
        EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
        ASSERT_EQ(s.textures.size(), 1u);
        EXPECT_EQ(s.textures[0].width, 2);
        expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 1, 0, 0);
        expectColor(surfaceAt(s, quadHit(s, 0.5, 0.5)).albedo, 0, 1, 0);
        expectColor(surfaceAt(s, quadHit(s, -0.5, -0.5)).albedo, 0, 0, 1);
        expectColor(surfaceAt(s, quadHit(s, 0.5, -0.5)).albedo, 1, 1, 1);
    }
}

TEST(GltfFeatures, AnImageThatDoesNotDecodeIsAWarningAndTheFactorShades) {
    std::ifstream in(fixture("quad_texture_data_uri.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    doc["images"][0]["uri"] = "data:image/png;base64," + base64("not a png");
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.5, 0.25, 1, 1};
    const Scene s = loadJson(doc, "broken_image.gltf");
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("image 0"), std::string::npos) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("base colour factor"), std::string::npos) << s.warnings[0];
    EXPECT_TRUE(s.textures.empty());
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0.5f, 0.25f, 1);
}

// Images of a format dacrt does not decode (whatever their mimeType), data URIs that are not
// base64, and bytes a reader fails on: one warning naming the image and what is wrong, the
// factor shades. (A GIF of 65535 x 65535 declared image/png once reached OpenImageIO's GIF
// reader, which threw: an internal error.)
TEST(GltfFeatures, ImagesDacrtDoesNotDecodeAreWarningsNamingTheImage) {
    const std::string gif = std::string("GIF89a\xFF\xFF\xFF\xFF\0\0\0,\0\0\0\0\xFF\xFF\xFF\xFF\0\x02\x02\x44\x01\0;", 29);
    const std::vector<std::tuple<std::string, std::string>> cases = {
        {"data:image/png;base64," + base64(gif), "it is GIF, declared image/png"},
        {"data:image/png;base64," + base64(std::string("v/1\x01\x02\0\0\0", 8)), "it is OpenEXR"},
        {"data:image/ktx2;base64," + base64(std::string("\xABKTX 20\xBB\r\n\x1A\n", 12)), "it is KTX2"},
        {"data:image/png;base64," + base64("#?RADIANCE\n"), "it is Radiance HDR"},
        {"data:image/jpeg;base64," + base64("<svg xmlns=\"http://www.w3.org/2000/svg\"/>"), "neither PNG, JPEG nor WebP"},
        {"data:image/webp;base64,UklG@kZ", "base64 has '@' at character 4"},
        {"data:image/webp;base64,UklGR", "a group of 4 cut short"},
        {"data:image/webp,RIFF", "is not base64"},
    };
    std::ifstream in(fixture("quad_texture_data_uri.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.5, 0.25, 1, 1};
    for (const auto& [uri, why] : cases) {
        SCOPED_TRACE(why);
        doc["images"][0]["uri"] = uri;
        const Scene s = loadJson(doc, "other_format.gltf");
        ASSERT_EQ(s.warnings.size(), 1u);
        EXPECT_NE(s.warnings[0].find("image 0"), std::string::npos) << s.warnings[0];
        EXPECT_NE(s.warnings[0].find(why), std::string::npos) << s.warnings[0];
        EXPECT_EQ(s.warnings[0].find(uri), std::string::npos) << "the URI is not repeated: " << s.warnings[0];
        EXPECT_TRUE(s.textures.empty());
        expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0.5f, 0.25f, 1);
    }
}

// tinygltf decodes data URIs of a few media types only; any other base64 one (image/webp for
// EXT_texture_webp, a made-up one) is decoded by dacrt, padded or not, and its bytes decide
// the format.
TEST(GltfFeatures, AnImageDataUriOfAnyMediaTypeDecodes) {
    std::ifstream in(fixture("quad_texture_data_uri.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    const std::string png = doc["images"][0]["uri"].get<std::string>().substr(std::string("data:image/png;base64,").size());
    std::string unpadded = png;
    while (unpadded.ends_with('=')) unpadded.pop_back();
    for (const std::string& uri : {"data:image/webp;base64," + png, "data:application/x-made-up;base64," + unpadded,
                                   "data:;base64," + png}) {
        SCOPED_TRACE(uri.substr(0, 40));
        doc["images"][0]["uri"] = uri;
        const Scene s = loadJson(doc, "webp_uri.gltf");
        EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
        ASSERT_EQ(s.textures.size(), 1u);
        expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 1, 0, 0);
        expectColor(surfaceAt(s, quadHit(s, 0.5, -0.5)).albedo, 1, 1, 1);
    }
}

TEST(GltfFeatures, TextureTransformAndWrapModes) {
    std::ifstream in(fixture("quad_texture_data_uri.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    // Offset by half the image in u with REPEAT: the left half now shows the right column.
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        {"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}};
    doc["extensionsUsed"] = {"KHR_texture_transform"};
    Scene s = loadJson(doc, "transformed.gltf");
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0, 1, 0);
    expectColor(surfaceAt(s, quadHit(s, 0.5, 0.5)).albedo, 1, 0, 0);
    // CLAMP_TO_EDGE: past the right edge the right column repeats.
    doc["samplers"][0]["wrapS"] = 33071;
    s = loadJson(doc, "clamped.gltf");
    expectColor(surfaceAt(s, quadHit(s, 0.5, 0.5)).albedo, 0, 1, 0);
    // MIRRORED_REPEAT with offset 1: u in [1, 2) reads 2 - u, so the left half shows the right
    // column (REPEAT would show the left one).
    doc["samplers"][0]["wrapS"] = 33648;
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {{"offset", {1.0, 0.0}}};
    s = loadJson(doc, "mirrored.gltf");
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0, 1, 0);
    // The order T R S: scale (2, 1) then offset 0.5 sends u = 0.05 (x = -0.9) to 0.6, the right
    // column; offsetting first would give 1.1, the left one (under REPEAT).
    doc["samplers"][0]["wrapS"] = 10497;
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
        {"offset", {0.5, 0.0}}, {"scale", {2.0, 1.0}}};
    s = loadJson(doc, "scaled.gltf");
    expectColor(surfaceAt(s, quadHit(s, -0.9, 0.5)).albedo, 0, 1, 0);
    // Rotation by pi/2: (u, v) -> (v, -u); u = v = 0.25 (top left) reads (0.25, -0.25), which
    // repeats to (0.25, 0.75): the bottom-left texel, blue.
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
        {"rotation", M_PI / 2}};
    s = loadJson(doc, "rotated.gltf");
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0, 0, 1);
}

TEST(GltfFeatures, TexelsAreSrgbDecodedAndLinearFilteredBetweenCentres) {
    const Scene s = loadGltf(fixture("quad_texture_grey.gltf"));
    const float grey = 0.21586050f;  // sRGB 128 / 255 in linear light
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.0)).albedo, grey, grey, grey);  // the grey texel's centre
    const float half = 0.5f * (grey + 1.0f);
    expectColor(surfaceAt(s, quadHit(s, 0.0, 0.0)).albedo, half, half, half);  // halfway to the white one
    expectColor(surfaceAt(s, quadHit(s, 0.99, 0.0)).albedo, 1, 1, 1);         // clamped past its centre
}

TEST(GltfFeatures, SmoothNormalsFollowTheirCornersUnderAMirroringNode) {
    // Each vertex's NORMAL is normalize(x, y, 1) of its position; under a node that mirrors x
    // (scale -1, 1, 1) positions and normals both flip x, and the loader swaps two corners of
    // every triangle: each corner's normal must still be normalize(x, y, 1) of its corner.
    const Mesh m = grid({-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, 3, 2);
    nlohmann::json doc = plainDocument(m);
    std::vector<glm::vec3> normals;
    for (const glm::vec3& p : m.positions) normals.push_back(glm::normalize(glm::vec3(p.x, p.y, 1.0f)));
    std::vector<unsigned char> data = bytesOf(m.positions);
    const std::vector<unsigned char> idx = bytesOf(m.indices), nrm = bytesOf(normals);
    data.insert(data.end(), idx.begin(), idx.end());
    const std::size_t normalOffset = data.size();
    data.insert(data.end(), nrm.begin(), nrm.end());
    doc["buffers"][0] = {{"byteLength", data.size()}, {"uri", dataUri(data)}};
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", normalOffset}, {"byteLength", nrm.size()}});
    doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", normals.size()}, {"type", "VEC3"}});
    doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2;
    doc["nodes"][0]["scale"] = {-1, 1, 1};
    doc["materials"] = {{{"doubleSided", true}}};
    doc["meshes"][0]["primitives"][0]["material"] = 0;
    const Scene s = loadJson(doc, "mirrored_normals.gltf");
    ASSERT_EQ(s.corners.normals.size(), s.triangleCount());
    for (std::size_t t = 0; t < s.triangleCount(); ++t) {
        const glm::vec3 v[3] = {s.triangles[t].v0, s.triangles[t].v1, s.triangles[t].v2};
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 expected = glm::normalize(glm::vec3(v[k].x, v[k].y, 1.0f));
            EXPECT_NEAR(glm::distance(s.corners.normals[t][std::size_t(k)], expected), 0.0f, 1e-6f) << t << " " << k;
        }
        // The corner swap keeps the front counter-clockwise: the geometric normal faces +z.
        EXPECT_GT(geometricNormal(s.triangles[t]).z, 0.0f) << t;
    }
    // The shading normal at a hit is the corners' interpolated, not the geometric (0, 0, 1).
    const Hit h = hitAt(s, 0, (glm::dvec3(s.triangles[0].v0) + glm::dvec3(s.triangles[0].v1)) * 0.5);
    EXPECT_GT(glm::length(glm::vec2(surfaceAt(s, h).normal)), 0.1f);
}

TEST(GltfFeatures, VertexColoursAreNormalizedBytesInterpolated) {
    const Scene s = loadGltf(fixture("quad_vertex_colors.gltf"));
    ASSERT_EQ(s.corners.colors.size(), s.triangleCount());
    // Corner (-1, -1) is red, (1, -1) green, (1, 1) blue, (-1, 1) white.
    Hit h = quadHit(s, -1.0, -1.0);
    expectColor(surfaceAt(s, h).albedo, 1, 0, 0);
    h = quadHit(s, 0.0, -1.0);  // halfway along the bottom edge
    expectColor(surfaceAt(s, h).albedo, 0.5f, 0.5f, 0);
}

TEST(GltfFeatures, SparseAccessorsAndAccessorsWithoutABufferView) {
    const Scene s = loadGltf(fixture("quad_sparse.gltf"));
    ASSERT_EQ(s.triangleCount(), 3u);
    EXPECT_EQ(s.triangles[0].v2, glm::vec3(2, 2, 0));  // vertex 2 replaced by the sparse part
    EXPECT_EQ(s.triangles[1].v1, glm::vec3(2, 2, 0));
    EXPECT_EQ(s.triangles[0].v0, glm::vec3(-1, -1, 0));
    EXPECT_EQ(s.triangles[2].v0, glm::vec3(0, 0, 0));  // no view and no sparse value: zero
    EXPECT_EQ(s.triangles[2].v1, glm::vec3(1, 0, 1));
    EXPECT_EQ(s.triangles[2].v2, glm::vec3(0, 1, 1));
}

TEST(GltfFeatures, QuantizedPositionsUnderADequantizingNodeEqualTheirFloatTwin) {
    const Scene q = loadGltf(fixture("quad_quantized.gltf"));
    const Scene plain = loadGltf(fixture("quad_quantized_twin.gltf"));
    ASSERT_EQ(q.triangleCount(), plain.triangleCount());
    for (std::size_t i = 0; i < q.triangleCount(); ++i) {
        EXPECT_EQ(q.triangles[i].v0, plain.triangles[i].v0);
        EXPECT_EQ(q.triangles[i].v1, plain.triangles[i].v1);
        EXPECT_EQ(q.triangles[i].v2, plain.triangles[i].v2);
    }
    EXPECT_EQ(q.triangles[0].v1, glm::vec3(2, -2, plain.triangles[0].v1.z));
    // Without the extension declared, quantized positions are refused by name.
    std::ifstream in(fixture("quad_quantized.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    doc.erase("extensionsUsed");
    doc.erase("extensionsRequired");
    EXPECT_NE(refusal(doc, "undeclared.gltf").find("KHR_mesh_quantization"), std::string::npos) << refusal(doc, "undeclared.gltf");
}

TEST(GltfFeatures, MeshoptCompressedMeshDecodesToItsPlainTwin) {
    const Mesh m = testMesh();
    const Scene plain = loadJson(plainDocument(m), "plain.gltf");
    std::vector<unsigned char> vertices(meshopt_encodeVertexBufferBound(m.positions.size(), 12));
    vertices.resize(meshopt_encodeVertexBuffer(vertices.data(), vertices.size(), m.positions.data(), m.positions.size(), 12));
    std::vector<unsigned char> indices(meshopt_encodeIndexBufferBound(m.indices.size(), m.positions.size()));
    indices.resize(meshopt_encodeIndexBuffer(indices.data(), indices.size(), m.indices.data(), m.indices.size()));
    std::vector<unsigned char> data = vertices;
    while (data.size() % 4) data.push_back(0);
    const std::size_t indexOffset = data.size();
    data.insert(data.end(), indices.begin(), indices.end());

    nlohmann::json doc = plainDocument(m);
    const std::size_t vertexBytes = m.positions.size() * 12, indexBytes = m.indices.size() * 4;
    doc["extensionsUsed"] = {"EXT_meshopt_compression"};
    doc["extensionsRequired"] = {"EXT_meshopt_compression"};
    doc["buffers"] = {{{"byteLength", data.size()}, {"uri", dataUri(data)}},
                      {{"byteLength", vertexBytes + indexBytes}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
    doc["bufferViews"] = {
        {{"buffer", 1}, {"byteLength", vertexBytes}, {"byteStride", 12},
         {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteLength", vertices.size()}, {"byteStride", 12},
                                                      {"count", m.positions.size()}, {"mode", "ATTRIBUTES"}}}}}},
        {{"buffer", 1}, {"byteOffset", vertexBytes}, {"byteLength", indexBytes},
         {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteOffset", indexOffset}, {"byteLength", indices.size()},
                                                      {"byteStride", 4}, {"count", m.indices.size()}, {"mode", "TRIANGLES"}}}}}}};
    const Scene packed = loadJson(doc, "meshopt.gltf");
    ASSERT_EQ(packed.triangleCount(), plain.triangleCount());
    // Lossless; the index codec may rotate a triangle's corners (keeping its winding).
    EXPECT_EQ(canonical(packed.triangles), canonical(plain.triangles));

    // Corrupted compressed bytes are refused naming the extension.
    nlohmann::json bad = doc;
    std::vector<unsigned char> broken = data;
    std::fill(broken.begin(), broken.begin() + 8, 0xFF);
    bad["buffers"][0]["uri"] = dataUri(broken);
    EXPECT_NE(refusal(bad, "broken_meshopt.gltf").find("EXT_meshopt_compression"), std::string::npos) << refusal(bad, "broken_meshopt.gltf");
}

TEST(GltfFeatures, DracoCompressedMeshDecodesToItsPlainTwin) {
    const Mesh m = testMesh();
    const Scene plain = loadJson(plainDocument(m), "plain.gltf");
    draco::Mesh mesh;
    mesh.set_num_points(std::uint32_t(m.positions.size()));
    draco::GeometryAttribute position;
    position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
    const int id = mesh.AddAttribute(position, true, std::uint32_t(m.positions.size()));
    for (std::uint32_t i = 0; i < m.positions.size(); ++i)
        mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(i), &m.positions[i]);
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        mesh.AddFace({draco::PointIndex(m.indices[t]), draco::PointIndex(m.indices[t + 1]), draco::PointIndex(m.indices[t + 2])});
    draco::Encoder encoder;  // no quantization: positions are stored losslessly
    encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
    draco::EncoderBuffer encoded;
    ASSERT_TRUE(encoder.EncodeMeshToBuffer(mesh, &encoded).ok());
    const std::vector<unsigned char> data(encoded.data(), encoded.data() + encoded.size());

    nlohmann::json doc = plainDocument(m);
    doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    doc["buffers"] = {{{"byteLength", data.size()}, {"uri", dataUri(data)}}};
    doc["bufferViews"] = {{{"buffer", 0}, {"byteLength", data.size()}}};
    doc["accessors"][0].erase("bufferView");
    doc["accessors"][1].erase("bufferView");
    doc["meshes"][0]["primitives"][0]["extensions"] = {
        {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", mesh.attribute(id)->unique_id()}}}}}};
    const Scene packed = loadJson(doc, "draco.gltf");
    ASSERT_EQ(packed.triangleCount(), plain.triangleCount());
    EXPECT_EQ(canonical(packed.triangles), canonical(plain.triangles));

    nlohmann::json bad = doc;
    bad["buffers"][0]["uri"] = dataUri(std::vector<unsigned char>(data.size(), 0x5A));
    EXPECT_NE(refusal(bad, "broken_draco.gltf").find("KHR_draco_mesh_compression"), std::string::npos) << refusal(bad, "broken_draco.gltf");
}

TEST(GltfFeatures, UnknownRequiredExtensionsAreRefusedByNameAndUsedOnesWarned) {
    nlohmann::json doc = plainDocument(testMesh());
    doc["extensionsUsed"] = {"EXT_made_up_a", "EXT_made_up_b"};
    const Scene s = loadJson(doc, "used.gltf");
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("EXT_made_up_a, EXT_made_up_b"), std::string::npos) << s.warnings[0];
    doc["extensionsRequired"] = {"EXT_made_up_b"};
    EXPECT_NE(refusal(doc, "required.gltf").find("requires the extension EXT_made_up_b"), std::string::npos) << refusal(doc, "required.gltf");
}

TEST(GltfFeatures, ScenesCamerasAndLights) {
    Scene s = loadGltf(fixture("quad_cameras_lights.gltf"));
    ASSERT_EQ(s.cameras.size(), 2u);
    ASSERT_TRUE(s.camera.has_value());
    EXPECT_EQ(s.camera->name, "top");
    EXPECT_EQ(s.camera->projection, Projection::Orthographic);
    EXPECT_DOUBLE_EQ(s.camera->ymag, 1.5);
    selectCamera(s, "side");
    EXPECT_EQ(s.camera->projection, Projection::Perspective);
    EXPECT_NEAR(s.camera->eye.x, 4.0, 1e-12);
    EXPECT_NEAR(s.camera->forward.x, -1.0, 1e-12);
    selectCamera(s, "0");
    EXPECT_EQ(s.camera->name, "top");
    try {
        selectCamera(s, "front");
        FAIL() << "selected";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("0 'top', 1 'side'"), std::string::npos) << e.what();
    }
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].type, LightType::Point);
    EXPECT_EQ(s.lights[0].name, "bulb");
    EXPECT_EQ(s.lights[0].color, glm::vec3(1, 0.5f, 0.25f));
    EXPECT_FLOAT_EQ(s.lights[0].intensity, 20.0f);
    EXPECT_EQ(s.lights[0].position, glm::dvec3(0, 2, 2));
    EXPECT_EQ(s.lights[1].type, LightType::Spot);
    EXPECT_FLOAT_EQ(s.lights[1].outerConeAngle, 0.5f);
    EXPECT_EQ(s.lights[1].direction, glm::dvec3(0, 0, -1));
    EXPECT_EQ(s.warnings.size(), 1u);  // EXT_unheard_of_but_optional, used only

    const Scene far = loadGltf(fixture("quad_cameras_lights.gltf"), {}, GltfSelection{.scene = "far", .animation = "", .time = 0.0});
    EXPECT_EQ(far.triangles[0].v0.z, -5.0f);
    EXPECT_EQ(far.lights.size(), 0u);
    EXPECT_EQ(far.cameras.size(), 1u);
    EXPECT_EQ(loadGltf(fixture("quad_cameras_lights.gltf"), {}, GltfSelection{.scene = "1", .animation = "", .time = 0.0}).triangles[0].v0.z, -5.0f);
    try {
        loadGltf(fixture("quad_cameras_lights.gltf"), {}, GltfSelection{.scene = "middle", .animation = "", .time = 0.0});
        FAIL() << "loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("0 'near', 1 'far'"), std::string::npos) << e.what();
    }
}

TEST(GltfFeatures, OrthographicRaysShareADirectionAndStartOnTheViewPlane) {
    Scene s = loadGltf(fixture("quad_cameras_lights.gltf"));
    const std::vector<Camera> cams = makeCameras(s, sceneBounds(s.triangles), {}, 1.0);
    ASSERT_EQ(cams[0].projection, Projection::Orthographic);
    const std::vector<Ray> rays = primaryRays(cams[0], 4, 4);
    for (const Ray& r : rays) {
        EXPECT_EQ(r.dir, rays[0].dir);
        EXPECT_EQ(r.origin.z, 3.0f);
        EXPECT_LE(std::abs(r.origin.x), 1.5f);
    }
    EXPECT_EQ(rays[0].origin, glm::vec3(-1.125f, 1.125f, 3.0f));  // pixel centre (0.5, 0.5) of 4 over [-1.5, 1.5]
    EXPECT_FALSE(viewFrustum(cams[0], 4, 4).has_value());
    CameraOptions fov;
    fov.fovDegrees = 30.0;
    EXPECT_THROW(makeCameras(s, sceneBounds(s.triangles), fov, 1.0), InputError);
}

TEST(GltfFeatures, ViewsOfAScenesCoordinatesStayWithinTheLimitOrNameTheFile) {
    // A flat quad 1.8e9 across, within the 1e9 limit: the front view framing it would stand at
    // z = 3.4e9; it stands at the limit instead.
    std::ifstream quad(fixture("quad_u8_camera.gltf"));
    nlohmann::json j = nlohmann::json::parse(quad);
    j["nodes"] = {{{"mesh", 0}, {"scale", {9e8, 9e8, 1}}}};
    j["scenes"] = {{{"nodes", {0}}}};
    j.erase("cameras");
    const Scene flat = loadJson(j, "flat.gltf");
    const std::vector<Camera> front = makeCameras(flat, sceneBounds(flat.triangles), {}, 4.0 / 3.0);
    EXPECT_EQ(front[0].eye.z, kMaxCoordinate);
    // The scene's own camera beyond the limit: refused naming the file and the camera.
    j = nlohmann::json::parse(std::ifstream(fixture("quad_u8_camera.gltf")));
    j["nodes"][1]["translation"] = {0, 0, 3e9};
    const Scene far = loadJson(j, "far.gltf");
    try {
        makeCameras(far, sceneBounds(far.triangles), {}, 1.0);
        FAIL() << "a camera outside the coordinate limit was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("far.gltf: camera: eye (0, 0, 3e+09) lies outside +-1e9"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("(camera 0 of node 1)"), std::string::npos) << e.what();
    }
}

TEST(GltfFeatures, SpecularGlossinessMaterialsShowTheirDiffuseColour) {
    // Older files (Khronos' glTF-pbrSpecularGlossiness samples) require the archived
    // extension; its diffuse texture and factor are the preview's base colour.
    std::ifstream in(fixture("quad_texture_data_uri.gltf"));
    nlohmann::json doc = nlohmann::json::parse(in);
    doc["materials"][0]["pbrMetallicRoughness"].erase("baseColorTexture");
    doc["materials"][0]["extensions"] = {{"KHR_materials_pbrSpecularGlossiness",
                                          {{"diffuseFactor", {0.5, 1, 1, 1}}, {"diffuseTexture", {{"index", 0}}}}}};
    doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
    doc["extensionsRequired"] = {"KHR_materials_pbrSpecularGlossiness"};
    const Scene s = loadJson(doc, "specgloss.gltf");
    EXPECT_TRUE(s.warnings.empty());
    expectColor(surfaceAt(s, quadHit(s, -0.5, 0.5)).albedo, 0.5f, 0, 0);
    expectColor(surfaceAt(s, quadHit(s, 0.5, -0.5)).albedo, 0.5f, 1, 1);
}

TEST(GltfFeatures, MeshoptExponentialFilterIsUndone) {
    // Positions stored through the EXPONENTIAL filter (8-bit exponent, 16-bit mantissas: lossy)
    // and the vertex codec decode to what the filter's own decoder gives: the twin is built
    // from those values.
    const Mesh m = testMesh();
    std::vector<std::uint32_t> filtered(m.positions.size() * 3);
    meshopt_encodeFilterExp(filtered.data(), m.positions.size() * 3, 4, 16, &m.positions[0].x);
    std::vector<std::uint32_t> expected = filtered;
    meshopt_decodeFilterExp(expected.data(), expected.size(), 4);
    Mesh twin = m;
    std::memcpy(twin.positions.data(), expected.data(), expected.size() * 4);
    const Scene plain = loadJson(plainDocument(twin), "plain.gltf");

    std::vector<unsigned char> vertices(meshopt_encodeVertexBufferBound(m.positions.size(), 12));
    vertices.resize(meshopt_encodeVertexBuffer(vertices.data(), vertices.size(), filtered.data(), m.positions.size(), 12));
    std::vector<unsigned char> data = vertices;
    while (data.size() % 4) data.push_back(0);
    const std::size_t indexOffset = data.size();
    const std::vector<unsigned char> idx = bytesOf(m.indices);
    data.insert(data.end(), idx.begin(), idx.end());
    nlohmann::json doc = plainDocument(m);
    const std::size_t vertexBytes = m.positions.size() * 12;
    doc["extensionsUsed"] = {"EXT_meshopt_compression"};
    doc["buffers"] = {{{"byteLength", data.size()}, {"uri", dataUri(data)}},
                      {{"byteLength", vertexBytes}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
    doc["bufferViews"] = {
        {{"buffer", 1}, {"byteLength", vertexBytes}, {"byteStride", 12},
         {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteLength", vertices.size()}, {"byteStride", 12},
                                                      {"count", m.positions.size()}, {"mode", "ATTRIBUTES"},
                                                      {"filter", "EXPONENTIAL"}}}}}},
        {{"buffer", 0}, {"byteOffset", indexOffset}, {"byteLength", idx.size()}}};
    const Scene packed = loadJson(doc, "meshopt_exp.gltf");
    ASSERT_EQ(packed.triangleCount(), plain.triangleCount());
    for (std::size_t i = 0; i < plain.triangleCount(); ++i) ASSERT_EQ(packed.triangles[i].v2, plain.triangles[i].v2) << i;
    EXPECT_NE(plain.triangles[0].v1, loadJson(plainDocument(m), "raw.gltf").triangles[0].v1) << "the filter should be lossy here";
}

TEST(GltfFeatures, DracoAttributesFollowTheirIds) {
    // Two Draco attributes whose unique ids are not the glTF order: NORMAL (added first) and
    // POSITION; each corner's decoded normal must be the one its position had.
    const Mesh m = testMesh();
    std::vector<glm::vec3> normals;
    for (const glm::vec3& p : m.positions) normals.push_back(glm::normalize(p - glm::vec3(0.2f, -0.1f, 0.3f)));
    draco::Mesh mesh;
    mesh.set_num_points(std::uint32_t(m.positions.size()));
    draco::GeometryAttribute normal, position;
    normal.Init(draco::GeometryAttribute::NORMAL, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
    position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, 12, 0);
    const int normalId = mesh.AddAttribute(normal, true, std::uint32_t(m.positions.size()));
    const int positionId = mesh.AddAttribute(position, true, std::uint32_t(m.positions.size()));
    for (std::uint32_t i = 0; i < m.positions.size(); ++i) {
        mesh.attribute(normalId)->SetAttributeValue(draco::AttributeValueIndex(i), &normals[i]);
        mesh.attribute(positionId)->SetAttributeValue(draco::AttributeValueIndex(i), &m.positions[i]);
    }
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        mesh.AddFace({draco::PointIndex(m.indices[t]), draco::PointIndex(m.indices[t + 1]), draco::PointIndex(m.indices[t + 2])});
    draco::Encoder encoder;
    encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);  // reorders points
    draco::EncoderBuffer encoded;
    ASSERT_TRUE(encoder.EncodeMeshToBuffer(mesh, &encoded).ok());
    const std::vector<unsigned char> data(encoded.data(), encoded.data() + encoded.size());
    nlohmann::json doc = plainDocument(m);
    doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    doc["buffers"] = {{{"byteLength", data.size()}, {"uri", dataUri(data)}}};
    doc["bufferViews"] = {{{"buffer", 0}, {"byteLength", data.size()}}};
    doc["accessors"][0].erase("bufferView");
    doc["accessors"][1].erase("bufferView");
    doc["accessors"].push_back({{"componentType", 5126}, {"count", m.positions.size()}, {"type", "VEC3"}});
    doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2;
    doc["meshes"][0]["primitives"][0]["extensions"] = {
        {"KHR_draco_mesh_compression",
         {{"bufferView", 0},
          {"attributes", {{"POSITION", mesh.attribute(positionId)->unique_id()}, {"NORMAL", mesh.attribute(normalId)->unique_id()}}}}}};
    const Scene s = loadJson(doc, "draco_normals.gltf");
    ASSERT_EQ(s.triangleCount(), m.indices.size() / 3);
    ASSERT_EQ(s.corners.normals.size(), s.triangleCount());
    for (std::size_t t = 0; t < s.triangleCount(); ++t) {
        const glm::vec3 v[3] = {s.triangles[t].v0, s.triangles[t].v1, s.triangles[t].v2};
        for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(glm::distance(s.corners.normals[t][std::size_t(k)], glm::normalize(v[k] - glm::vec3(0.2f, -0.1f, 0.3f))), 0.0f, 1e-5f)
                << t << " " << k;
    }
}
