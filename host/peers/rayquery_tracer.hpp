#pragma once
// The rayquery backend: the device's own ray tracing (VK_KHR_ray_query) over an acceleration
// structure built on the device in the same command buffer as the trace. A peer, measured
// like Embree: not watertight by specification (docs/benchmarks.md reports its error).
#include <memory>
#include <optional>
#include <vector>

#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"  // RayQueryBuild and its names
#include "cpu/trace_result.hpp"
#include "gpu/context.hpp"
#include "gpu/pipeline_cache.hpp"

namespace dacrt {

// The triangles on the device with their acceleration structure, kept across frames.
class RayQueryScene {
public:
    // Throws InputError naming what the device lacks when it has no ray query.
    RayQueryScene(gpu::Context& context, gpu::PipelineCache& pipelines, const std::vector<Triangle>& triangles,
                  RayQueryBuild build);
    ~RayQueryScene();
    RayQueryScene(const RayQueryScene&) = delete;
    RayQueryScene& operator=(const RayQueryScene&) = delete;

    // One frame in one command buffer: the vertices uploaded again and the structure built
    // (the first frame, and every frame of a dynamic scene) or updated (refit), then the rays
    // traced within their segments (ray.tmin <= t <= ray.tmax as Vulkan specifies it, which
    // differs from dacrt's t > tmin only at a triangle through a ray's start; a miss is
    // missHit(ray)): the closest hit, or for HitQuery::Any the first hit the traversal commits
    // (gl_RayFlagsTerminateOnFirstHitEXT), its t and primitive. phases holds upload, build
    // (or refit: the structure's part alone), dispatch (build and trace together, as the
    // device ran them) and readback; the gpu report the timestamps.
    TraceResult trace(const std::vector<Ray>& rays, HitQuery query = HitQuery::Closest);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Shows onPlan what the frame will hold on the device besides the acceleration structure, whose
// size only the driver knows (it is in the result's plan after the frame). Returns the result
// of a frame stopped there (its plan, no hit) where onPlan says stop; nothing where the frame
// goes on (or no hook is given).
std::optional<TraceResult> stoppedAtPlan(const FrameGeometry& geometry, const PlanHook& onPlan);

// A single frame: the scene built for it (dynamic), then traced for the frame's query.
TraceResult traceRayQuery(const FrameGeometry& geometry, gpu::Context& context, gpu::PipelineCache& pipelines,
                          const PlanHook& onPlan = {});

}  // namespace dacrt
