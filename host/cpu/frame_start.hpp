#pragma once
// What every cpu tracer does before its first node: the plan of the frame's own arrays, and
// every ray's best hit at its segment's end.
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/trace_result.hpp"

namespace dacrt {

// The frame's rays, hits, triangles and triangle bounds, from the counts (rayCount rays:
// the frame's own where not given; its rays are then not read).
void planFrameInputs(const FrameGeometry& geometry, MemoryPlan& plan);
void planFrameInputs(const FrameGeometry& geometry, std::uint64_t rayCount, MemoryPlan& plan);

// Every ray's best hit starts at its segment's end (missHit). Returns whether every ray has
// the first one's segment, bit for bit (TraversalBuffers::raysShareSegment), found in the same
// pass over the rays, in chunks side by side on the pool (none: on the calling thread).
bool startHits(const FrameGeometry& geometry, std::vector<Hit>& hits, ThreadPool* pool);

}  // namespace dacrt
