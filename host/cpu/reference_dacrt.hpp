#pragma once
// A reference DACRT that reads like the paper: Mora 2011's basic recursion ("Naive
// ray-tracing: a divide-and-conquer approach"; the source thesis's Code 2.1), scalar, with one
// list of ray ids and one of triangle ids per node instead of the optimised traversal's
// in-place pivots, packets and SIMD kernels. It runs the project's predicates (the watertight
// leaf test, the ray and triangle filters on cells widened by the filter margin, the
// acceptance rule: docs/correctness.md), so it gives brute force's hits bit for bit, and the
// optimised cpu backends are tested against it (tests/cpu/test_reference_dacrt.cpp).
#include <cstdint>
#include <vector>

#include "cpu/frame_geometry.hpp"
#include "core/shader_layout.hpp"

namespace dacrt {

// When a node stops splitting and tests every pair (the paper's "naive" leaf).
struct ReferenceLeafLimits {
    std::uint32_t rays = 8;       // fewer live rays than this: a leaf
    std::uint32_t triangles = 8;  // fewer triangles than this: a leaf
    std::uint32_t maxDepth = 48;  // coincident triangles never separate: stop splitting here
};

// One hit per ray of the frame, for its query (closest or any) and child order (NearSide or
// PerRay), each ray within its segment [tmin, tmax].
std::vector<Hit> traceReferenceDacrt(const FrameGeometry& geometry, const ReferenceLeafLimits& limits = {});

}  // namespace dacrt
