#pragma once
// The CPU backends: brute force, sequential DACRT, and the parallel scheme.
#include <functional>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/options.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// Called now and then, from any thread, with the fraction of the frame done.
using ProgressHook = std::function<void(double)>;

// Every ray against every triangle (threads split the rays).
TraceResult traceBrute(const FrameGeometry& geometry, ThreadPool& pool, const PlanHook& onPlan = {},
                       const ProgressHook& onProgress = {});

// Whether traceCpu traces a frame of these counts as subtrees (subtrees.hpp): the cpu backend
// without regions asked for, a frame large enough for more than one thread (kSequentialBelowRays),
// and tracesAsSubtrees.
bool cpuTracesAsSubtrees(std::uint64_t rays, std::uint64_t tracedTriangles, HitQuery query, const TraceOptions& options,
                         unsigned workers);

// What traceSequential allocates for a frame of rayCount rays over g's traced triangles, from
// the counts: g's rays are read only where they are an image's (packets), so that a pass can
// plan a group of rays before making them (made_pass_groups.hpp).
MemoryPlan sequentialPlan(const FrameGeometry& geometry, std::uint64_t rayCount, const DacrtOptions& options);

// One DACRT over the whole scene on the calling thread.
TraceResult traceSequential(const FrameGeometry& geometry, const DacrtOptions& options, const PlanHook& onPlan = {});

// The parallel scheme: division into regions, Step 1 (one DACRT per region), then the
// transfer rounds; work items of a step run on the pool.
TraceResult traceParallel(const FrameGeometry& geometry, const TraceOptions& options, ThreadPool& pool,
                          const PlanHook& onPlan = {});

// The bands side by side (imageBands, image_bands.hpp): each a sequential DACRT over the
// traced triangles its rays can reach (bandTriangleIds), its rays the band's ids into the
// frame's arrays (packets and hits are the frame's), on one worker at a time. Exact as
// traceSequential is: no division, no transfer rounds. The cpu backend's primary frames where
// --regions is not given (docs/cpu-reference.md, "Image bands").
TraceResult traceImageBands(const FrameGeometry& geometry, const DacrtOptions& options, ThreadPool& pool,
                            const std::vector<std::uint32_t>& bands, const PlanHook& onPlan = {});

// The backend options.backend names: brute, cpu-seq or cpu. Throws InputError first when the
// options ask it for DACRT options it does not take, or do not combine (checkTraceOptions).
TraceResult traceCpu(const FrameGeometry& geometry, const TraceOptions& options, ThreadPool& pool,
                     const PlanHook& onPlan = {}, const ProgressHook& onProgress = {});

}  // namespace dacrt
