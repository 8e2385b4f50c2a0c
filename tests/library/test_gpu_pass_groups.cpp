// A gpu pass through the dispatcher, as every frame's passes go: on a device that takes a CPU's
// defaults (lavapipe) its rays are one region's ray groups, the cpu backend's batches; with
// regions or ray groups asked for, they are what was asked. Brute force's visibility either
// way, under the validation layers. Skipped without a Vulkan device.
#include <gtest/gtest.h>

#include <exception>
#include <functional>
#include <memory>
#include <string>

#include "cpu/cpu_tracers.hpp"
#include "cpu/image_bands.hpp"
#include "gpu/device_defaults.hpp"
#include "support/dispatcher_passes.hpp"
#include "support/frames.hpp"
#include "support/gpu_support.hpp"

namespace dacrt {
namespace {

using namespace test;

struct Shape {
    unsigned regions;
    std::uint32_t rayGroups;
};

// Each pass of the set on brute force, then on gpu with each requested shape: `expect` gives
// the shape the trace must report for the shape asked for.
void expectPassShapes(const SecondaryPassSet& set, BackendDispatcher& dispatcher,
                      const std::function<Shape(Shape)>& expect) {
    forEachPassAgainstBruteForce(set, dispatcher, [&](const FrameGeometry& primary, const SecondaryPass& pass,
                                                      const BackendDispatcher::PassTrace& reference) {
        BackendRequest request;
        request.trace.threads = 2;
        request.trace.backend = Backend::Gpu;
        for (Shape asked : {Shape{0, 0}, Shape{3, 0}, Shape{0, 3}, Shape{1, 1}}) {
            request.trace.regions = asked.regions;
            request.gpuTuning.rayGroups = asked.rayGroups;
            const BackendDispatcher::PassTrace t = dispatcher.traceSecondary(primary, set.primary.hits, pass, request);
            const std::string shape = std::to_string(asked.regions) + " regions, " + std::to_string(asked.rayGroups) +
                                      " ray groups asked for";
            EXPECT_EQ(t.rays, reference.rays) << shape;
            EXPECT_TRUE(identicalVisibility(reference.result.hits, t.result.hits)) << shape;
            ASSERT_TRUE(t.result.gpu.has_value()) << shape;
            const Shape want = expect(asked);
            if (want.regions) {
                EXPECT_EQ(t.result.regions, want.regions) << shape;
            }
            if (want.rayGroups) {
                EXPECT_EQ(t.result.gpu->rayGroups, want.rayGroups) << shape;
            }
        }
    });
    EXPECT_EQ(dispatcher.validationErrors(), 0u);
}

// A dispatcher for the gpu backend under the validation layers, or none (why says why).
std::unique_ptr<BackendDispatcher> validatingGpuDispatcher(std::string& why) {
    try {
        return std::make_unique<BackendDispatcher>(DeviceChoice{"", true}, std::vector<Backend>{Backend::Gpu});
    } catch (const std::exception& e) {
        why = e.what();
        return nullptr;
    }
}

TEST(GpuPassGroups, OnACpuDeviceAPassIsOneRegionsRayGroupsUnlessAskedOtherwise) {
    DACRT_REQUIRE_GPU(context);
    std::string why;
    const std::unique_ptr<BackendDispatcher> dispatcher = validatingGpuDispatcher(why);
    if (!dispatcher) GTEST_SKIP() << "no Vulkan device: " << why;
    const gpu::DeviceInfo& device = context->info();
    const bool cpuDevice = gpu::takesCpuDefaults(device, GpuProfile::Auto);
    // These passes make a few thousand rays: one batch, then as many as the device's threads.
    const std::uint32_t batches = gpu::defaultGpuRegions(device, GpuProfile::Auto);
    const auto expect = [&](Shape asked) {
        if (asked.regions == 0 && asked.rayGroups == 0) return cpuDevice ? Shape{1, batches} : Shape{0, 0};
        return asked;
    };
    expectPassShapes(shapesSecondaryPasses(), *dispatcher, expect);
    expectPassShapes(shapesUnderACeilingPasses(), *dispatcher, expect);
}

// A primary frame: where the cpu backend would cut the image into at least two bands a core
// (few triangles for its rays), one region whose ray groups are those bands; elsewhere the
// device's regions. cpu-seq's hits either way.
TEST(GpuPassGroups, OnACpuDeviceAPrimaryFrameOfFewTrianglesForItsRaysIsOneRegionsRayGroups) {
    DACRT_REQUIRE_GPU(context);
    std::string why;
    const std::unique_ptr<BackendDispatcher> dispatcher = validatingGpuDispatcher(why);
    if (!dispatcher) GTEST_SKIP() << "no Vulkan device: " << why;
    const gpu::DeviceInfo& device = context->info();
    if (!gpu::takesCpuDefaults(device, GpuProfile::Auto)) GTEST_SKIP() << "not a CPU device: its regions stay";
    const unsigned cores = gpu::defaultGpuRegions(device, GpuProfile::Auto);
    const Scene s = shapesScene();
    bool banded = false, divided = false;
    // 640 wide, a batch holds 12 rows of tiles (65,536 rays): 12 x cores + 1 of them make
    // cores + 1 batches, rounded up to 2 x cores bands. 6 rows of tiles make at most 6.
    const int tall = 8 * (12 * int(cores) + 1);
    for (const int height : {48, tall}) {
        SCOPED_TRACE("640x" + std::to_string(height));
        const Frame frame(shapesScene(), defaultCamera(s, 640, height), 640, height);
        const std::vector<std::uint32_t> bands = imageBands(frame.geometry, cores);
        BackendRequest request;
        request.trace.threads = 2;
        request.trace.backend = Backend::Gpu;
        const TraceResult r = dispatcher->trace(frame.geometry, request);
        EXPECT_TRUE(identicalHits(frame.trace(Backend::CpuSeq).hits, r.hits));
        ASSERT_TRUE(r.gpu.has_value());
        if (bands.size() > 2 * std::size_t(cores)) {
            banded = true;
            EXPECT_EQ(r.regions, 1u);
            EXPECT_EQ(r.gpu->rayGroups, std::min<std::size_t>(bands.size() - 1, gpu::kMostDefaultRayGroups));
        } else {
            divided = true;
            EXPECT_EQ(r.regions, cores);
        }
    }
    if (cores > 1) EXPECT_TRUE(banded) << "the tall image is bands on a device of " << cores << " cores";
    EXPECT_TRUE(divided) << "the short image keeps the regions";
    EXPECT_EQ(dispatcher->validationErrors(), 0u);
}

}  // namespace
}  // namespace dacrt
