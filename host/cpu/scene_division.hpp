#pragma once
// Host side of the parallel scheme (Pahins 2015, with this project's exactness rules):
// division axis, slab regions, ray and triangle binning, and the transfer schedule.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"

namespace dacrt {

struct Division {
    int axis = 0;
    std::vector<Region> regions;               // slabs in increasing order along axis
    std::vector<std::uint8_t> raysTowardLow;   // region has rays travelling to lower regions
    std::vector<std::uint8_t> raysTowardHigh;
    std::vector<std::uint32_t> rayIds;         // rays that meet the scene box, region by region
    std::vector<std::uint32_t> triIds;         // every triangle once per region it overlaps
    std::uint64_t culledRays = 0;
    std::uint64_t straddlerCopies = 0;         // triIds.size() minus the triangle count
    std::uint64_t mostRegionRays = 0;          // the largest region's ray and triangle counts
    std::uint64_t mostRegionTriangles = 0;
    bool complete = false;                     // false: stopped after the plan, ids not filled
};

struct TransferPair {
    std::uint32_t rayRegion;  // whose live rays travel
    std::uint32_t triRegion;  // whose triangles they are traced against
};

struct TransferRound {
    std::string name;
    std::vector<TransferPair> pairs;  // distinct ray ranges and distinct triangle ranges
};

// The face of the scene box that most rays enter through is the one the camera sees most;
// of the two axes lying in that face, the one whose slabs share rays and triangles most
// evenly is chosen.
int chooseDivisionAxis(const FrameGeometry& geometry, unsigned regionCount);

// Splits the scene box into regionCount equal slabs (the source's midpoint subdivision,
// generalised to any count), bins each ray into the first region it meets and each triangle into every
// region whose widened box it overlaps. Counts first, then appends the id arrays to plan
// (and what planTracer adds for the tracer's own buffers, from the counts) and fills them,
// so the memory is known before anything is traced. onPlan returning false stops before the fill.
using DivisionPlanHook = std::function<void(const Division&, MemoryPlan&)>;
Division divideScene(const FrameGeometry& geometry, unsigned regionCount, int axis, ThreadPool& pool,
                     MemoryPlan& plan, const PlanHook& onPlan = {}, const DivisionPlanHook& planTracer = {});

// What the division's plan is computed from: the counts its first passes measure.
struct DivisionCounts {
    std::uint64_t rays = 0;
    std::uint64_t tracedTriangles = 0;
    std::size_t rayChunks = 1, triangleChunks = 1;  // the binning's chunks
    unsigned regions = 1;
    int axis = 0;
    std::uint64_t rayIds = 0;          // rays binned (those that meet the scene box)
    std::uint64_t triangleIds = 0;     // triangle copies, straddlers counted in each region
    std::uint64_t culledRays = 0;
    std::uint64_t straddlerCopies = 0;
    std::uint64_t transferPairs = 0;
};

// The division's buffers and work lines, from its counts.
MemoryPlan planDivision(const DivisionCounts& counts);

// Round s pairs region j's live rays with region j - s (first pass) or j + s (second pass),
// only where region j has rays travelling that way: for rays leaving one camera this is the
// source's CameraIntersect test, made exact. raysKnown false: the rays are binned later (on the
// device), so every region's rays may travel both ways.
std::vector<TransferRound> transferSchedule(const Division& division, bool raysKnown = true);

}  // namespace dacrt
