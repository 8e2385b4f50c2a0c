#pragma once
// A tracer: one backend with its options, its threads and (gpu, rayquery) its Vulkan device,
// opened once and kept for every trace.
//
// What a trace costs. dacrt's backends keep nothing between traces: each one computes the
// triangles' bounds (phase "bounds") and traces, what every frame of a dynamic scene needs (the
// gpu keeps the triangles on the device while the scene's triangles do not change). The peers
// keep their acceleration structure over the last scene they traced, as their users keep it
// (one per option set, so that a sweep over their build modes keeps each): the first trace of
// a scene builds it (phase "build"; rayquery "allocate" first); every later trace (or occluded)
// of that scene is the next frame of a dynamic scene, which a dynamic structure rebuilds (into
// the last one's memory, "build") and a refit one refits ("refit"), while a static one is only
// traced, and built again once the scene's positions changed (TraceScene::setPositions). The
// secondary passes of traceFrame trace the structure their frame left (the ray queries rebuild
// or refit theirs in every trace, passes included: the device's build and trace share one
// command buffer). A peer's trace of another scene frees what was kept for the last one; the
// Tracer reads a scene only while tracing it.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <dacrt/backend_tuning.hpp>
#include <dacrt/devices.hpp>
#include <dacrt/frame.hpp>
#include <dacrt/options.hpp>
#include <dacrt/rays.hpp>
#include <dacrt/results.hpp>
#include <dacrt/scene.hpp>

namespace dacrt {

struct TracerOptions {
    TraceOptions trace;     // the backend, its threads and sub-scenes, the DACRT options, the skips
    GpuTuning gpu;          // gpu only
    EmbreeOptions embree;   // embree only (its build threads are the trace's)
    RayQueryBuild rayQueryBuild = RayQueryBuild::Dynamic;  // rayquery only
    std::string device;     // gpu, rayquery: a device index or part of its name; empty: the best
    bool validate = false;  // gpu, rayquery: under the Vulkan validation layers (validationErrors())
};

// The checks the Tracer's constructor makes, without opening a device: a command checks its
// options before loading anything. Throws InputError as the constructor does.
void checkTracerOptions(const TracerOptions& options);

class Tracer {
public:
    // Checks the options against the backend and opens its device (gpu, rayquery). Throws
    // InputError on an option the backend does not take (the message names it as the command
    // line does) or a device that is missing or does not match.
    explicit Tracer(const TracerOptions& options = {});
    Tracer(Tracer&&) noexcept;
    Tracer& operator=(Tracer&&) noexcept;
    ~Tracer();

    // Each ray's closest hit within its segment. Throws InputError where the trace's plan
    // exceeds this machine's memory (before it is allocated) or a buffer the device's limits.
    TraceOutput trace(const TraceScene& scene, const RayBatch& rays);

    // Whether each ray hits anything within its segment (shadow and occlusion rays): the
    // visibility is exact; the hit is any of those in the segment, and Embree names none of
    // them (kUnnamedPrimitive, t the ray's tmin).
    TraceOutput occluded(const TraceScene& scene, const RayBatch& rays);

    // A camera's frame (RayBatch::fromCamera) and then its secondary passes from the primary
    // hits, by the same backend: what `dacrt render` traces. onPlan sees each pass's plan first.
    FrameOutput traceFrame(const TraceScene& scene, const RayBatch& cameraRays, const std::vector<FramePass>& passes,
                           const PlanCallback& onPlan = {}, const ProgressCallback& onProgress = {});

    // The memory and work plan trace() would follow, without tracing: no ray meets a
    // triangle. The plan depends on more than the counts: the skips and the division into
    // sub-scenes decide it, so their passes over the scene and rays run (as for `dacrt render
    // --plan`). Embree allocates its structure itself: its plan bounds it from the triangle
    // count (the most Embree 3.13.5 was measured to take, docs/benchmarks.md).
    FramePlan plan(const TraceScene& scene, const RayBatch& rays);

    // Later traces use these options, on the threads and device already open: a sweep over
    // DACRT options or backends pays for the device and its pipelines once. Throws InputError
    // as the constructor does, on another device or validation choice than the open one, and
    // on gpu or rayquery for a tracer made without them (which opened no device).
    void setOptions(const TracerOptions& options);

    // Frees what this tracer keeps between traces: the peers' structures, and the gpu's
    // resident triangles and kept buffers. The next trace of a scene makes them again, as a
    // scene's first trace does: for a caller that holds more than memory allows at once (a
    // bench run whose configurations would each keep their own: docs/benchmarks.md).
    void releaseKept();

    const TracerOptions& options() const;
    // gpu, rayquery: the Vulkan device opened, "name (driver)"; empty where none is open.
    std::string device() const;
    // Its properties and limits (as listDevices() gives them); none where no device is open.
    std::optional<VulkanDeviceProperties> deviceProperties() const;
    // What the gpu backend chooses on that device where GpuTuning and TraceOptions leave it
    // open, under these options' GpuTuning::profile (docs/gpu.md); none where no device is open.
    struct GpuDefaults {
        unsigned regions = 0;           // sub-scenes (TraceOptions::regions 0)
        std::uint32_t rayGroups = 0;    // work items per sub-scene and round, with that many sub-scenes (the
                                        // discrete profile: on average, shared out among them by estimated cost)
        std::uint32_t leafBalance = 0;  // GpuTuning::leafBalance where no leaf limit is given (0: off)
    };
    std::optional<GpuDefaults> gpuDefaults() const;
    // Vulkan validation errors so far (with options.validate; 0 otherwise).
    std::uint32_t validationErrors() const;
    // Their messages, as the validation layers gave them.
    std::vector<std::string> validationMessages() const;

    struct Impl;  // the library's own

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace dacrt
