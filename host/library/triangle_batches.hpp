#pragma once
// A gpu frame over more triangles than the device holds at once (its plan throws
// gpu::DeviceLimitExceeded before allocating): its triangles traced in batches, each batch a
// frame of its own over every ray, and the batches' hits merged by the tie rule every backend
// follows (the smaller t, then the smaller primitive id; any hit for occlusion), so that the
// frame finds the hits one trace would.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "cpu/frame_geometry.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// The frame over the triangles `ids` (ascending, a subset of the geometry's traced ones), as a
// frame of its own: those triangles and their bounds copied in id order (the device holds a
// frame's whole triangle array), their box, and no triangles' version (nothing resident).
// Its hits name batch positions: toFrameIds maps them back to the frame's ids.
struct TriangleBatch {
    std::vector<std::uint32_t> ids;
    std::vector<Triangle> triangles;
    std::vector<Bounds> bounds;
    FrameGeometry geometry;

    TriangleBatch(const FrameGeometry& frame, std::vector<std::uint32_t> ids);
    TriangleBatch(const TriangleBatch&) = delete;
    TriangleBatch& operator=(const TriangleBatch&) = delete;
    void toFrameIds(std::vector<Hit>& hits) const;
};

// The ids in `parts` runs of about equal counts, in id order (a scene's triangles lie together
// by mesh and instance, so a run stays compact).
std::vector<std::vector<std::uint32_t>> splitIds(const std::vector<std::uint32_t>& ids, std::size_t parts);

// Each ray's answer over both batches: the closer hit (equal t: the smaller primitive id), or
// for any-hit queries the hit where either has one. Counters, phases, the gpu's report add up.
void mergeBatch(TraceResult& into, const TraceResult& batch, HitQuery query);

// Traces `geometry` with `traceOne`; where that throws gpu::DeviceLimitExceeded, traces its
// triangles in as many batches as the excess asks (each split again while it still exceeds)
// and merges them. The result's plan is the first batch's, with a work line naming the batches.
// `planLines` are work lines the trace adds to the plan it shows (the batches planned).
using BatchTrace = std::function<TraceResult(const FrameGeometry&, const std::vector<WorkLine>& planLines)>;
TraceResult traceInTriangleBatches(const FrameGeometry& geometry, const BatchTrace& traceOne);

}  // namespace dacrt
