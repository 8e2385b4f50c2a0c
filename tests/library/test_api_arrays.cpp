// The public API's array forms that numpy callers use (the Python module, python/): rays as six
// floats each (RayBatch::fromRays), a batch's rays written back (writeRays), the hit
// triangles' geometric normals, and the refusal of arrays larger than this machine's memory.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "core/system_memory.hpp"
#include "support/api_support.hpp"

namespace dacrt {
namespace {

using test::expectInputError;
using test::onBackend;
using test::sameHits;

using test::kRoomScene;

// Origins and directions interleaved, six floats per ray.
std::vector<float> interleaved(const test::RayArrays& r) {
    std::vector<float> six;
    for (std::size_t i = 0; i < r.origins.size() / 3; ++i) {
        six.insert(six.end(), r.origins.begin() + std::ptrdiff_t(3 * i), r.origins.begin() + std::ptrdiff_t(3 * i + 3));
        six.insert(six.end(), r.directions.begin() + std::ptrdiff_t(3 * i), r.directions.begin() + std::ptrdiff_t(3 * i + 3));
    }
    return six;
}

TEST(ApiArrays, RaysAsSixFloatsGiveTheSeparateArraysHits) {
    const test::SceneArrays s = test::randomSceneArrays(31, 1500);
    const test::RayArrays r = test::randomRayArrays(32, 6000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const std::vector<float> six = interleaved(r);
    Tracer tracer(onBackend(Backend::Cpu, 2));
    for (DirectionLength length : {DirectionLength::Normalize, DirectionLength::AsGiven}) {
        const TraceOutput apart = tracer.trace(scene, RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax, length));
        const TraceOutput together = tracer.trace(scene, RayBatch::fromRays(six, {}, r.tmax, length));
        EXPECT_GT(test::hitCount(apart.hits), apart.hits.size() / 10);
        EXPECT_TRUE(sameHits(together.hits, apart.hits));
    }
    expectInputError([&] { RayBatch::fromRays(std::vector<float>(7, 1.0f)); }, "rays: 7 floats are not whole rays");
    expectInputError([&] { RayBatch::fromRays(six, std::vector<float>{0.0f}); }, "tmin: 1 values for 6000 rays");
    std::vector<float> zero = six;
    zero[6 * 5 + 3] = zero[6 * 5 + 4] = zero[6 * 5 + 5] = 0.0f;
    expectInputError([&] { RayBatch::fromRays(zero); }, "ray 5: origin");
}

// A camera's rays written out and traced again as given are the camera's rays: the same hits.
TEST(ApiArrays, WrittenCameraRaysTraceAsTheCamerasBitForBit) {
    const TraceScene scene = TraceScene::load(kRoomScene);
    const RayBatch camera = RayBatch::fromCamera(scene, {}, 64, 48);
    std::vector<float> six(6 * camera.size());
    camera.writeRays(six);
    for (std::size_t i = 0; i < camera.size(); ++i) {
        const float* d = &six[6 * i + 3];
        ASSERT_NEAR(std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]), 1.0, 1e-6) << i;
    }
    const RayBatch again = RayBatch::fromRays(six, {}, {}, DirectionLength::AsGiven);
    for (Backend b : {Backend::CpuSeq, Backend::Cpu, Backend::Brute}) {
        Tracer tracer(onBackend(b, 2));
        EXPECT_TRUE(sameHits(tracer.trace(scene, again).hits, tracer.trace(scene, camera).hits)) << int(b);
    }
    std::vector<float> wrong(6 * camera.size() - 1);
    expectInputError([&] { camera.writeRays(wrong); }, "writeRays: 18431 floats for 3072 rays");
}

TEST(ApiArrays, GeometricNormalsFollowTheCallersNumbering) {
    // Triangle 1 has no area and is dropped; 0 faces +z, 2 faces -z (clockwise seen from +z).
    const std::vector<float> p = {0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 1, 1, 1, 2, 2, 1, 0, 0, 3, 0, 4, 3, 4, 0, 3};
    const std::vector<std::uint32_t> i = {0, 1, 2, 3, 4, 5, 6, 7, 8};
    const TraceScene scene = TraceScene::fromArrays(p, i);
    const std::vector<std::uint32_t> ids = {0, 2, kNoPrimitive, kUnnamedPrimitive};
    std::vector<float> n(3 * ids.size(), -7.0f);
    scene.geometricNormals(ids, n);
    EXPECT_EQ(n, (std::vector<float>{0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 0}));
    std::vector<float> one(3);
    expectInputError([&] { scene.geometricNormals(std::vector<std::uint32_t>{1}, one); },
                     "primitive id 1 names no triangle of the scene (2 traced, numbered as given, those with no area dropped)");
    expectInputError([&] { scene.geometricNormals(std::vector<std::uint32_t>{3}, one); }, "primitive id 3 names no triangle");
    expectInputError([&] { scene.geometricNormals(ids, one); }, "geometricNormals: 3 floats for 4 primitive ids");

    // A loaded scene's hits: unit normals perpendicular to the hit triangle's edges (the room's
    // are axis-aligned walls, curved spheres and a torus).
    const TraceScene room = TraceScene::load(kRoomScene);
    const TraceOutput out = Tracer(onBackend(Backend::Cpu, 2)).trace(room, RayBatch::fromCamera(room, {}, 32, 24));
    std::vector<std::uint32_t> hitIds;
    for (const RayHit& h : out.hits) hitIds.push_back(h.primitive);
    std::vector<float> normals(3 * hitIds.size());
    room.geometricNormals(hitIds, normals);
    for (std::size_t k = 0; k < hitIds.size(); ++k) {
        const double len = std::hypot(double(normals[3 * k]), double(normals[3 * k + 1]), double(normals[3 * k + 2]));
        EXPECT_NEAR(len, 1.0, 1e-6) << k;
    }
}

// Arrays whose batch or scene would not fit in memory are refused by size, before a value is read.
TEST(ApiArrays, RefusesArraysLargerThanMemory) {
    const std::uint64_t memory = physicalMemoryBytes();
    if (memory == 0) GTEST_SKIP() << "the system does not say how much memory it has";
    const std::size_t rays = std::size_t(memory / 16);  // 64 bytes each, at least, once made
    const std::vector<float> small(6, 1.0f);
    // The spans name more floats than `small` holds: none is read, the size alone is refused.
    expectInputError([&] { RayBatch::fromRays(std::span<const float>(small.data(), 6 * rays)); },
                     "rays needs");
    expectInputError([&] { RayBatch::fromArrays(std::span<const float>(small.data(), 3 * rays),
                                                std::span<const float>(small.data(), 3 * rays)); },
                     "bytes of memory");
    const std::vector<std::uint32_t> index(3, 0);
    expectInputError([&] { TraceScene::fromArrays(small, std::span<const std::uint32_t>(index.data(), 3 * rays)); },
                     "triangles needs");
}

}  // namespace
}  // namespace dacrt
