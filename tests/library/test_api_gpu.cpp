// The public API's gpu backend: the same hits as cpu-seq, bit for bit, for closest and any
// hit and for a camera's rays, with no validation error. Skipped without a Vulkan device.
#include <exception>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "support/api_support.hpp"

namespace dacrt {
namespace {

using test::onBackend;
using test::sameHits;

// The gpu tracer under the validation layers, or the reason there is none.
std::optional<Tracer> gpuTracer(std::string& why) {
    TracerOptions o = onBackend(Backend::Gpu, 2);
    o.validate = true;
    try {
        return Tracer(o);
    } catch (const std::exception& e) {  // InputError, or the Vulkan loader's failure
        why = e.what();
        return std::nullopt;
    }
}

TEST(ApiGpu, SameHitsAsCpuSeq) {
    std::string why;
    std::optional<Tracer> gpu = gpuTracer(why);
    if (!gpu) GTEST_SKIP() << "no Vulkan device: " << why;
    const test::SceneArrays s = test::randomSceneArrays(21, 2000);
    const test::RayArrays r = test::randomRayArrays(22, 10000);
    const TraceScene scene = TraceScene::fromArrays(s.positions, s.indices, s.singleSided);
    const RayBatch rays = RayBatch::fromArrays(r.origins, r.directions, {}, r.tmax);
    Tracer cpuSeq(onBackend(Backend::CpuSeq));
    EXPECT_TRUE(sameHits(gpu->trace(scene, rays).hits, cpuSeq.trace(scene, rays).hits));
    const std::vector<RayHit> any = gpu->occluded(scene, rays).hits;
    const std::vector<RayHit> closest = cpuSeq.trace(scene, rays).hits;
    ASSERT_EQ(any.size(), closest.size());
    for (std::size_t i = 0; i < any.size(); ++i) ASSERT_EQ(any[i].hit(), closest[i].hit()) << i;

    const RayBatch camera = RayBatch::fromCamera(scene, {}, 96, 64);
    const TraceOutput image = gpu->trace(scene, camera);
    EXPECT_TRUE(sameHits(image.hits, cpuSeq.trace(scene, camera).hits));
    EXPECT_FALSE(image.counters.device.empty());
    EXPECT_GT(image.timings.dispatchMs, 0.0);
    EXPECT_FALSE(gpu->plan(scene, camera).memory.empty());
    EXPECT_EQ(gpu->validationErrors(), 0u);
}

}  // namespace
}  // namespace dacrt
