#pragma once
// The tuning of the backends that take their own options: the gpu's dispatch shape, Embree's
// build and the ray queries' build. Plain data, shared by the public API and the backends
// themselves.
#include <cstdint>
#include <optional>

namespace dacrt {

// Whose defaults the gpu backend takes where GpuTuning and TraceOptions leave the dispatch's
// shape open (docs/gpu.md). Auto: the device's own kind. Cpu: a CPU device's (lavapipe): one
// region per core, a few work items, one subgroup per workgroup. Discrete: a discrete GPU's,
// thousands of work items in Step 1, on any device: lavapipe then runs the shape a GPU would
// run, with the same hits. The driver's loop limit (llvmpipe) applies under every profile.
enum class GpuProfile { Auto, Cpu, Discrete };

// The cpu profile's leaf balance (GpuTuning::leafBalance), measured on lavapipe (docs/gpu.md,
// "The leaf balance": 16 to 24 gave the fastest frames on the Bunny, the Dragon and the room).
constexpr std::uint32_t kCpuProfileLeafBalance = 20;
// The largest leaf balance the kernel takes (its square must fit 32 bits; far beyond any use).
constexpr std::uint32_t kMostLeafBalance = 4096;

struct GpuTuning {
    std::uint32_t workgroupSize = 0;  // 0: the profile's default (gpu::defaultWorkgroupSize)
    std::uint32_t rayGroups = 0;      // 0: the profile's default (gpu::defaultRayGroups)
    GpuProfile profile = GpuProfile::Auto;
    // The leaf balance (docs/gpu.md, "The leaf balance"): a node is also a leaf where its
    // ray/triangle tests number fewer than this many per id a split would partition; 0: off.
    // None: the profile's default, on under the cpu profile where neither leaf limit is given
    // (the leaf limits are then off: the balance alone decides), off under the discrete one.
    std::optional<std::uint32_t> leafBalance;
    // Caps below the device's own limits, for tests (docs/gpu.md): every array larger than
    // bufferBytes is reached by device address, as arrays beyond maxStorageBufferRange are, in
    // chunks of at most chunkBytes (rounded down to a multiple of 192 bytes; else of
    // maxMemoryAllocationSize); memoryBytes lowers the memory a frame's device buffers may take
    // together. 0: the device's limit.
    std::uint64_t bufferBytes = 0;
    std::uint64_t chunkBytes = 0;
    std::uint64_t memoryBytes = 0;
    // Runs the kernel built with its stage clocks (docs/gpu.md, "Where the kernel's time
    // goes"): DeviceReport::stageTicks then tells the kernel's time apart by stage. Needs the
    // device's subgroup clock (VulkanDeviceProperties::subgroupClock); frames whose arrays are
    // reached by device address are refused with it.
    bool stageClocks = false;
};

// How the BVH follows the frames, as Embree's users configure each case.
// Dynamic: RTC_SCENE_FLAG_DYNAMIC with RTC_BUILD_QUALITY_LOW, a new BVH every frame (a scene
// whose topology changes). Refit: one scene kept across frames, its geometry at
// RTC_BUILD_QUALITY_REFIT, the vertex buffer updated and recommitted each frame (valid while
// only vertices move). Static: RTC_BUILD_QUALITY_HIGH, built once, frames pay the trace only.
enum class EmbreeBuild { Dynamic, Refit, Static };

struct EmbreeOptions {
    // RTC_SCENE_FLAG_ROBUST: no leaks through shared edges. On by default, unlike Embree
    // itself: without it Embree leaks real pixels on the Bunny's orbit (docs/benchmarks.md).
    bool robust = true;
    unsigned threads = 0;  // threads of Embree's BVH build; 0: every core
    EmbreeBuild build = EmbreeBuild::Dynamic;
    // 16-wide packets (rtcIntersect16, rtcOccluded16): on 4x4 pixel tiles with the coherent
    // flag where the rays are an image, else on runs of 16 consecutive rays; false: one
    // rtcIntersect1 or rtcOccluded1 per ray.
    bool packets = true;
    // The rays' image width, for the tiles, where a trace names none; 0: not an image
    // (secondary rays).
    std::uint32_t imageWidth = 0;
    // The face rule as intersection and occlusion filters where some triangles are
    // single-sided (the rule every backend applies); false: both faces hit, Embree's fastest,
    // which gives the same image wherever no back face is visible (closed meshes seen from
    // outside).
    bool faceFilter = true;

    bool operator==(const EmbreeOptions&) const = default;
};

// How the ray queries' acceleration structure follows the frames, as a Vulkan user builds for
// each case. Dynamic: PREFER_FAST_BUILD, rebuilt every frame. Refit: ALLOW_UPDATE, updated
// every frame (valid while only vertices move). Static: PREFER_FAST_TRACE, built once.
enum class RayQueryBuild { Dynamic, Refit, Static };

}  // namespace dacrt
