#pragma once
// The image bands of a primary frame on the cpu backend (traceImageBands: one sequential DACRT
// a band, a band a worker at a time): where they begin, weighed by their work, and the
// triangles each band's rays can reach. The frame ends with its costliest band: equal bands of
// rows left one of the Dragon's two workers idle for a quarter of the frame, its triangles
// lying mostly in the image's lower half; and a band whose rows crossed the DACRT's first
// split filtered the far side's triangles down several levels for a few rows of rays.

#include <cstdint>
#include <utility>
#include <vector>

#include <glm/common.hpp>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"

namespace dacrt {

// How many bands imageBands cuts the frame into for `workers` workers (0 where it does not):
// as many as rayBatches gives for batches of passBatchRays' size, as a multiple of the workers,
// in tile rows, at most one a row of tiles.
std::size_t imageBandCount(const FrameGeometry& geometry, unsigned workers);

// A closest-hit frame of an image's rays in imageBandCount bands of whole rows of 8x8 tiles:
// where each band starts, then the end, each band as near an equal share of tileRowWork as
// whole rows allow, equal rows where that is empty. Empty where the frame is no such image, a
// worker is alone, or one band would hold it.
std::vector<std::uint32_t> imageBands(const FrameGeometry& geometry, unsigned workers);

// The bands' edges between one another, as planes through a perspective camera's apex: which
// bands' rays can hit a triangle, from its bounds. A band drops a box that lies below its
// bottom edge or above its top edge by more than the view frustum skip's slack (outsideFrustum:
// 2^-12 of the distance to the box's farthest corner, taken here in float32 as 2^-11 of that
// distance's L1 norm, which float32's few roundings of the sum, at most 10 u of it, cannot
// bring under the L2 bound): then every vertex lies outside that edge as outsideFrustum asks,
// and no ray of the band can hit the triangle. The image's own top and bottom edges are the
// view frustum skip's, not tested here. The bands' triangles are part of the bands, which
// --no-skip subscenes turns off; --no-skip frustum does not.
class BandEdges {
public:
    // startRows: each band's first pixel row, then the image's rows (frustum.rows).
    BandEdges(const ViewFrustum& frustum, const std::vector<std::uint32_t>& startRows);
    // The first and the last band whose rays may hit a triangle within these bounds (first >
    // last: none). Every band between them is taken too: a box beyond an edge on both sides of
    // a band (behind the camera) may leave bands out between two it reaches.
    std::pair<std::uint32_t, std::uint32_t> bandsOf(const Bounds& b) const {
        const glm::vec3 lo = b.lo - apex_, hi = b.hi - apex_;
        const glm::vec3 far = glm::max(glm::abs(lo), glm::abs(hi));
        const float slack = 0x1p-11f * (far.x + far.y + far.z);
        std::uint32_t first = std::uint32_t(up_.size()) + 1, last = 0;
        bool reachesPrevious = true;  // band 0 has no top edge but the image's
        for (std::uint32_t k = 0; k < up_.size(); ++k) {
            const glm::vec3 atLo = up_[k] * lo, atHi = up_[k] * hi;
            // The largest and smallest n . (corner - apex) over the box's corners: no vertex
            // lies farther towards band k, or towards band k + 1.
            const glm::vec3 most = glm::max(atLo, atHi), least = glm::min(atLo, atHi);
            const bool reachesK = reachesPrevious && !(most.x + most.y + most.z < -slack);  // not below band k
            if (reachesK) first = std::min(first, k), last = k;
            reachesPrevious = !(least.x + least.y + least.z > slack);  // band k + 1: not above its top
        }
        if (reachesPrevious) first = std::min(first, std::uint32_t(up_.size())), last = std::uint32_t(up_.size());
        return {first, last};
    }
    // bandsOf for the bounds of ids[0, count) (bounds[0, count) where ids is null), in SIMD
    // lanes (simd::bandsOfBounds): the same answers, into first and last.
    void bandsOfEach(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, std::uint32_t* first,
                     std::uint32_t* last) const;

private:
    glm::vec3 apex_;
    std::vector<glm::vec3> up_;  // up_[k]: the edge between bands k and k + 1, its normal towards band k
};

// For each band (imageBands' starts, in rays, whole image rows, then the end), the traced
// triangles its rays can reach (BandEdges), ascending: one pass over the traced triangles'
// bounds in chunks on the pool, then the bands' lists. Every traced triangle in each band where
// the frame has no view frustum of its rays' rows from their shared origin. InternalError where
// a start is inside a row.
std::vector<std::vector<std::uint32_t>> bandTriangleIds(const FrameGeometry& geometry,
                                                        const std::vector<std::uint32_t>& bands, ThreadPool& pool);

// The estimated work of each row of 8x8 tiles: a sample of the traced triangles, each counted
// (for the triangles it stands for) in the row its bounds' centre projects into, and a sample of
// each row's rays tested against the scene box, each weighing a twentieth of a triangle from
// outside the box and one from inside. Empty where the frame has no view frustum of its rows (an
// orthographic camera, rays the library did not make) or nothing to weigh.
std::vector<double> tileRowWork(const FrameGeometry& geometry);

// Where each of `bands` bands of tile rows begins, then the row count, each band holding as
// near an equal share of `rowWork` as whole rows allow and at least one row (bands at most the
// rows).
std::vector<std::uint32_t> bandsOfEqualWork(const std::vector<double>& rowWork, std::size_t bands);

}  // namespace dacrt
