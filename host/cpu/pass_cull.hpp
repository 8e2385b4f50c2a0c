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
#include <vector>

#include "core/thread_pool.hpp"
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
    // Whether a box meets a marked cell (boxes over many cells are kept unlooked).
    bool mayMeet(const glm::vec3& lo, const glm::vec3& hi) const;
    unsigned cellsAlongLongest() const { return longest_; }

private:
    // Cells from[k]..to[k] along the grid's axis k, inclusive.
    struct CellSpan {
        int from[3], to[3];
    };
    int cellOf(float x, int k) const;  // along the grid's axis k
    // The cells of the box around p grown by twice the margin, each bound rounded outwards.
    CellSpan cellsNear(const glm::dvec3& p) const;
    void markCells(const CellSpan& cells);
    void markRay(const Ray& ray);

    unsigned longest_ = 1;
    // The grid's axes: axis_[0] the shortest side's (along a word), then the other two; n_,
    // lo_ and scale_ are in that order.
    int axis_[3] = {0, 1, 2};
    int n_[3] = {1, 1, 1};
    glm::vec3 lo_{};      // the grid's corner: the scene box's
    glm::vec3 scale_{};   // cells per unit along each axis (0 on a flat axis)
    glm::dvec3 clipLo_{}, clipHi_{};  // the scene box widened by twice the margin
    double grow_ = 0.0;               // twice the margin
    std::uint64_t* rows_ = nullptr;
};

// What a pass's cull keeps, with the buffers it reuses from pass to pass (fresh memory is
// slow to touch on a VM: a pass must not allocate in proportion to the scene each time).
struct PassCull {
    TriangleSkips skips;                  // applied: the kept triangles (withSkips)
    std::uint64_t outsideRays = 0;        // dropped: no ray's segment passes their cells
    bool raysTested = false;              // the grid was built (the skip was on)
    bool directionShared = false;         // the rays share one direction: back faces tested
    unsigned cellsAlongLongest = 0;       // the grid's resolution
    std::vector<std::uint8_t> verdict;    // per triangle, reused
    std::vector<std::uint64_t> rows;      // the grid's marks, reused
};

// Culls the triangles of pass frame g (its rays are the pass's) that switches allow: those
// outside the rays' cells (switches.passRays) and, where every ray has the same direction,
// single-sided ones facing away from it (switches.backFaces). Fills cull.skips.
// cellsAlongLongest: the grid's resolution; 0 chooses it from the rays' lengths, so that
// marking them costs a fraction of the pass over the triangles.
void cullForPass(const FrameGeometry& g, const SkipSwitches& switches, ThreadPool& pool, PassCull& cull,
                 unsigned cellsAlongLongest = 0);

// Whether cullForPass may drop triangles of a pass of at most mostRays rays over `triangles`
// triangles (oneDirection: its rays share one, as a directional light's shadow rays do): the
// gpu, which makes a pass's rays on the device, makes them on the host for the cull only then.
bool passCullMayDrop(std::uint64_t mostRays, std::size_t triangles, bool oneDirection, const SkipSwitches& switches);

// The pass cull's lines of the work plan.
void planPassCull(const FrameGeometry& g, const SkipSwitches& switches, const PassCull& cull, MemoryPlan& plan);

}  // namespace dacrt
