#pragma once
// A cheap estimate, made on the host before tracing, of how much of its region's Step 1 work
// each binned ray brings (docs/gpu.md, "The gpu profiles"): what ray groups of equal cost are
// cut by (gpu/work_plan.hpp).
#include <cstdint>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/scene_division.hpp"

namespace dacrt::gpu {

// For each entry of division.rayIds: how many of its region's triangle bounds, seen from the
// rays' shared origin, cover the ray's cell of a grid laid over the region's ray directions
// (about one cell per ray). A ray that no bound covers is culled near the root of its region's
// tree; one covered by many passes near many triangles, down to the leaves. Empty where the
// rays do not share an origin (secondary rays, several cameras): there is no view to project
// into. A region whose rays do not all lie within 90 degrees of their mean direction gets 1
// for every ray (its groups stay of equal ray counts).
std::vector<std::uint32_t> estimateStep1RayCosts(const FrameGeometry& geometry, const Division& division,
                                                 ThreadPool& pool);

}  // namespace dacrt::gpu
