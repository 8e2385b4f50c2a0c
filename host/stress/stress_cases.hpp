#pragma once
// The stress suite's generators (docs/stability.md): scenes and rays built to break
// watertightness, split-plane handling and degenerate-geometry handling. Rays whose exact
// counterparts provably cross a closed surface are marked, so that a miss there is a leak.
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "cpu/frame_geometry.hpp"

namespace dacrt {

// Where a ray that starts on a surface starts, and the triangles it cannot hit at any t > 0
// (docs/stability.md, "Self-intersection"): a hit on one of them is a self-intersection.
struct SurfaceStart {
    std::string where;                   // the case's start point and the reasons, for messages
    glm::dvec3 normal{0.0};              // the start triangle's unit normal, on the ray's side
    std::vector<std::uint32_t> ruledOut;  // ascending
};

constexpr std::uint32_t kNoSurfaceStart = 0xFFFFFFFFu;

struct StressCase {
    std::string family;  // watertight | split-plane | degenerate | surface-rays
    std::string name;
    std::vector<Triangle> triangles;
    std::vector<Ray> rays;              // one shared origin (primary rays), or each its own
    std::vector<std::uint8_t> mustHit;  // 1: the ray crosses a closed surface, so a miss is a leak
    // Groups of triangles with identical vertex arrays: a ray hitting one of them must report
    // the lowest id (the tie rule), whichever backend traced it.
    std::vector<std::vector<std::uint32_t>> coincidentGroups;
    // Any: only visibility (a hit or not) is compared with brute force, as for shadow rays.
    HitQuery query = HitQuery::Closest;
    // Rays that start on surfaces: per ray an index into starts, or kNoSurfaceStart (also
    // for every ray when empty). (Initialized here so that the other families' brace
    // initializers may leave them out.)
    std::vector<SurfaceStart> starts{};
    std::vector<std::uint32_t> startOf{};

    std::size_t mustHitCount() const;
};

// Small: the CTest `stress` suite (about 10^6 rays in all). Large: `dacrt stress`, finer
// meshes and more rays per case.
enum class StressSize { Small, Large };

std::vector<std::string> stressFamilies();  // every family name, in run order

// Watertightness: closed meshes (icosphere, torus, perturbed sphere, boxes, long thin
// cylinders) at scales 1e-4 to 1e6 and offsets up to 1e6, shot from inside at vertices, edge
// midpoints and random directions, and from outside through vertices, edges and the inside.
std::vector<StressCase> watertightCases(StressSize size, std::uint64_t seed);

// Triangles in split planes, vertices on cell and region boundaries, rays inside split
// planes, the camera on split planes inside the scene, axis-parallel and grazing rays.
std::vector<StressCase> splitPlaneCases(StressSize size, std::uint64_t seed);

// Zero-area, needle and sliver triangles, repeated vertices, a 10^6 size ratio, coincident
// triangles, and triangles that all straddle the first split.
std::vector<StressCase> degenerateCases(StressSize size, std::uint64_t seed);

// Secondary rays made as the renderer makes them (shared::surfaceOfHit, occlusionRay,
// shadowRay, segmentRay), from vertices, edges and faces of closed meshes seen from outside
// and inside, and from points in and near concave creases, at the watertightness family's
// scales and offsets; closest-hit and any-hit queries.
std::vector<StressCase> surfaceCases(StressSize size, std::uint64_t seed);

// The scene of the determinism checks: a room with shapes and split-plane grids, seen by a
// pinhole camera standing on the first split planes.
StressCase determinismCase(StressSize size);

// The named families' cases; throws InputError on an unknown family name.
std::vector<StressCase> stressCases(const std::vector<std::string>& families, StressSize size, std::uint64_t seed);

}  // namespace dacrt
