// Cost per element of the kernel's building blocks on a Vulkan device (one workgroup, GPU
// timestamps), beside the CPU's cost of the same predicate. Not a test: a measurement for
// docs/gpu.md. Run: build/tests/dacrt_bench_gpu_blocks [DEVICE]
#include <chrono>
#include <cstdio>
#include <numeric>
#include <random>

#include "core/camera.hpp"
#include "cpu/traversal.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/compute_pipeline.hpp"
#include "gpu/device_defaults.hpp"
#include "gpu/dispatch_recorder.hpp"
#include "gpu/embedded_shaders.hpp"
#include "gpu/pipeline_cache.hpp"

using namespace dacrt;

int main(int argc, char** argv) {
    gpu::Context context(gpu::ContextOptions{argc > 1 ? argv[1] : "", false});
    std::printf("device: %s (%s)\n", context.info().name.c_str(), context.info().driver.c_str());
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const std::uint32_t rayCount = 100000, triCount = 100000;
    std::vector<Ray> rays;
    std::vector<Hit> hits;
    std::vector<Triangle> tris;
    std::vector<Bounds> bounds;
    for (std::uint32_t i = 0; i < rayCount; ++i) {
        rays.push_back(makeRay({u(rng) * 0.1f, u(rng) * 0.1f, 3.0f}, {u(rng), u(rng), -1.0}));
        hits.push_back(missHit());
    }
    for (std::uint32_t i = 0; i < triCount; ++i) {
        Triangle t{};
        t.v0 = glm::vec3(u(rng), u(rng), u(rng));
        t.v1 = t.v0 + glm::vec3(0.01f, 0.0f, 0.0f);
        t.v2 = t.v0 + glm::vec3(0.0f, 0.01f, 0.0f);
        tris.push_back(t);
        bounds.push_back(triangleBounds(t));
    }
    std::vector<std::uint32_t> rayIds(rayCount), triIds(triCount);
    std::iota(rayIds.begin(), rayIds.end(), 0u);
    std::iota(triIds.begin(), triIds.end(), 0u);
    gpu::DacrtBindingSet set(context, gpu::planDacrtBuffers(gpu::DacrtBufferCounts{
                                          .rays = rayCount,
                                          .triangles = triCount,
                                          .rayIds = rayCount,
                                          .triangleIds = triCount,
                                          .regions = 1,
                                          .workItems = 1,
                                          .maxDepth = 0,
                                      }));
    auto upload = [&](std::uint32_t binding, const auto& v) { set[binding].upload(v.data(), v.size() * sizeof(v[0])); };
    upload(DACRT_BINDING_RAYS, rays);
    upload(DACRT_BINDING_TRIANGLES, tris);
    upload(DACRT_BINDING_TRIANGLE_BOUNDS, bounds);
    upload(DACRT_BINDING_HITS, hits);
    upload(DACRT_BINDING_RAY_IDS, rayIds);
    upload(DACRT_BINDING_TRI_IDS, triIds);
    const std::uint32_t subgroup = context.info().subgroupSize;
    for (std::uint32_t workgroup : {subgroup, 4 * subgroup}) {
        // The kernel's loop budget on this device: under one a partition's run of tests is
        // unrolled (keptOfRun), as the kernel runs it there.
        const gpu::KernelSpecialization specialization{.workgroupSize = workgroup,
                                                       .rayLimit = 16,
                                                       .triLimit = 16,
                                                       .maxDepth = 48,
                                                       .loopBudget = gpu::loopBudgetOf(context.info())};
        gpu::ComputePipeline pipeline(context, gpu::workgroupTestSpirv(), DACRT_BINDING_COUNT, sizeof(WorkgroupTestPush),
                                      specialization.values(), "bench");
        set.bindTo(pipeline);
        // Each block runs twice and the second run is reported: the first also pays for the
        // first touch of the scratch memory and the driver's lazy set-up.
        auto run = [&](const char* name, const WorkgroupTestPush& push, double elements) {
            gpu::DispatchRecorder recorder(context, 2);
            recorder.dispatch(name, pipeline, 1, &push);
            recorder.dispatch(name, pipeline, 1, &push);
            recorder.submitAndWait();
            const double ms = recorder.timingsMs()[1].second;
            std::printf("workgroup %3u  %-28s %8.2f ms  %6.1f ns per element\n", workgroup, name, ms, ms * 1e6 / elements);
        };
        WorkgroupTestPush push{};
        push.rayScratchHalf = rayCount;
        push.triScratchHalf = triCount;
        push.loopProbe = 2;
        push.lo = glm::vec3(-0.05f);
        push.hi = glm::vec3(0.05f, 0.05f, 3.5f);
        push.mode = 0;
        push.end = 40000;
        run("ray partition (40k rays)", push, 40000);
        push.mode = 1;
        push.lo = glm::vec3(-0.5f);
        push.hi = glm::vec3(0.5f);
        run("triangle partition (40k)", push, 40000);
        push.mode = 2;
        push.lo = glm::vec3(-1.5f);
        push.hi = glm::vec3(1.5f);
        push.end = 64;
        push.triEnd = 600;
        run("leaf 64 rays x 600 tris", push, 64 * 600);
        push.end = 8;
        push.triEnd = 3000;
        run("leaf 8 rays x 3000 tris", push, 8 * 3000);
    }
    using Clock = std::chrono::steady_clock;
    std::size_t crossing = 0;
    const auto t0 = Clock::now();
    for (std::uint32_t i = 0; i < 40000; ++i)
        crossing += shared::rayMayCrossCell(rays[i], glm::vec3(-0.05f), glm::vec3(0.05f, 0.05f, 3.5f), kNoHitT);
    const auto t1 = Clock::now();
    Hit best = missHit();
    for (std::uint32_t i = 0; i < 64; ++i)
        for (std::uint32_t j = 0; j < 600; ++j) testTriangle(rays[i], tris[j], j, best);
    const auto t2 = Clock::now();
    std::printf("cpu (this host, one thread): ray/box test %.1f ns, ray/triangle test %.1f ns (%zu crossing, hit %u)\n",
                std::chrono::duration<double, std::nano>(t1 - t0).count() / 40000,
                std::chrono::duration<double, std::nano>(t2 - t1).count() / (64 * 600), crossing, best.prim);
    return 0;
}
