#pragma once
// The triangle skip of a secondary pass: a pass of few rays (shadow rays from the visible
// surfaces, short occlusion rays) reaches few of the scene's triangles, and every triangle
// it cannot reach would still be divided, filtered and binned. The rays' segments, clipped
// to the scene box, are marked in a grid of cells over the box; a triangle whose bounds meet
// no marked cell is dropped. Exact by construction (docs/correctness.md, "Skips"): the marked
// cells cover every point within twice the filter margin of a segment, and a hit lies within
// the margin of its triangle's bounds. Where the rays share one direction (a directional
// light's shadow rays), single-sided triangles facing away from it are dropped as well.
#include <cstdint>
#include <limits>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/cull_lanes.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/options.hpp"
#include "cpu/triangle_skips.hpp"

namespace dacrt {

// The cells the rays' segments pass through, over the scene box.
class RayGrid {
public:
    // At most this many cells along the box's longest side, and kWordCells along its
    // shortest, whose rows of cells are one word of bits each.
    static constexpr unsigned kMaxCells = 128;
    static constexpr unsigned kWordCells = 64;

    // Marks every cell within twice g.margin of a ray's segment [tmin, tmax] clipped to the
    // scene box, cellsAlongLongest cells along its longest side (1 to kMaxCells). rows is the
    // marks' storage (a word per row of cells along x), reused from pass to pass.
    void mark(const FrameGeometry& g, unsigned cellsAlongLongest, std::vector<std::uint64_t>& rows, ThreadPool& pool);
    unsigned cellsAlongLongest() const { return longest_; }
    // The grid's axes, whose simd::cellsOfBoxes gives the cells a box covers.
    const simd::GridAxes& axes() const { return axes_; }
    // Whether box i of cells, the cells cells.first[k][i] .. cells.last[k][i] along each of the
    // grid's axes k, holds a marked cell (boxes over many rows of cells are kept unlooked).
    bool meetsCells(const simd::BoxCells& cells, std::uint32_t i) const;

private:
    // Cells from[k]..to[k] along the grid's axis k, inclusive.
    struct CellSpan {
        int from[3], to[3];
    };
    void markCells(const CellSpan& cells);
    void markRay(const Ray& ray, simd::PieceEndCells& ends);

    unsigned longest_ = 1;
    // The grid's axes: axes_.axis[0] the shortest side's (along a word), then the other two.
    simd::GridAxes axes_;
    glm::dvec3 clipLo_{}, clipHi_{};  // the scene box widened by twice the margin
    double grow_ = 0.0;               // twice the margin
    std::uint64_t* rows_ = nullptr;
};

// A box of points in float64.
struct PointBox {
    glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
    void extend(const glm::dvec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void extend(const PointBox& b) { extend(b.lo), extend(b.hi); }
    double diagonal() const { return glm::length(hi - lo); }
};

// What the cull's back-face tests read of a pass's rays, gathered ray by ray where they are
// made (add, in the pass's order; merge, the survey of the rays that follow): the first ray's
// origin, direction and tmax, whether every ray has that direction and that tmax bit for bit,
// and the boxes of the origins and of the ends (origin + tmax dir in float64, as the cull's own
// survey computes them). cullFromSurvey then needs no pass over the rays.
struct RaySurvey {
    std::uint64_t rays = 0;
    glm::vec3 firstOrigin{0.0f}, firstDir{0.0f};
    float firstTmax = 0.0f;
    bool sameDirection = true, sameTmax = true;
    PointBox origins, ends;
    void add(const Ray& ray);
    void merge(const RaySurvey& later);
};

// What a pass's cull keeps, with the buffers it reuses from pass to pass (fresh memory is
// slow to touch on a VM: a pass must not allocate in proportion to the scene each time).
struct PassCull {
    // Applied: the kept triangles (withSkips). Its singleSided stays 0: counting them would
    // read the triangles the grid drops, which the cull never reads.
    TriangleSkips skips;
    std::uint64_t outsideRays = 0;        // dropped: no ray's segment passes their cells
    bool raysTested = false;              // the grid was built (the skip was on)
    bool directionShared = false;         // the rays share one direction: back faces tested
    bool endShared = false;               // the rays' segments end at one point: faces toward it tested
    unsigned cellsAlongLongest = 0;       // the grid's resolution
    std::vector<std::uint8_t> verdict;    // per triangle, reused
    std::vector<std::uint64_t> rows;      // the grid's marks, reused
};

// Culls the triangles of pass frame g (its rays are the pass's) that switches allow: those
// outside the rays' cells (switches.passRays) and, with switches.backFaces, single-sided ones
// facing away from the rays' shared direction where they have one (a directional light's
// shadow rays), or facing toward the point where every segment ends where they share one
// (a point or spot light's). Fills cull.skips.
// cellsAlongLongest: the grid's resolution; 0 chooses it from the rays' lengths, so that
// marking them costs a fraction of the pass over the triangles.
void cullForPass(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool, PassCull& cull,
                 unsigned cellsAlongLongest = 0);

// cullForPass without the grid (the caller has found that it does not pay for the pass's
// rays), its back-face tests decided from a survey of the rays taken as they were made: the
// same verdicts as cullForPass's for those rays with the grid off (the survey's boxes and
// flags are what its passes over the rays find).
void cullFromSurvey(const FrameGeometry& g, const RaySurvey& survey, const SkipSwitches& switches, ThreadPool& pool,
                    PassCull& cull);

// Whether cullForPass may test anything for a pass of these rays over `triangles` triangles
// (the grid pays for itself, or the first rays share a direction or an end): it reads a few of
// them. Where it does not, the pass's geometry need not be made for the cull (cullNothing
// says so).
bool passCullTests(const std::vector<Ray>& rays, std::size_t triangles, const Box& sceneBox, const SkipSwitches& switches,
                   unsigned cellsAlongLongest = 0);
// The cull of a pass that tests nothing: every triangle traced, unlisted.
void cullNothing(PassCull& cull);

// Whether cullForPass may drop triangles of a pass of at most mostRays rays over `triangles`
// triangles (sharedFacing: its rays share a direction or an end, as a light's shadow rays do):
// the gpu, which makes a pass's rays on the device, makes them on the host for the cull only
// then.
bool passCullMayDrop(std::uint64_t mostRays, std::size_t triangles, bool sharedFacing, const SkipSwitches& switches);

// The pass cull's lines of the work plan.
void planPassCull(const FrameGeometry& g, const SkipSwitches& switches, const PassCull& cull, MemoryPlan& plan);

}  // namespace dacrt
