#pragma once
// The image bands of a primary frame on the cpu backend (traceImageBands: one sequential DACRT
// a band, a band a worker at a time): where they begin, weighed by their work, and the
// triangles each band's rays can reach. The frame ends with its costliest band: equal bands of
// rows left one of the Dragon's two workers idle for a quarter of the frame, its triangles
// lying mostly in the image's lower half; and a band whose rows crossed the DACRT's first
// split filtered the far side's triangles down several levels for a few rows of rays.

#include <array>
#include <cstdint>
#include <vector>

#include <glm/common.hpp>

#include "core/thread_pool.hpp"
#include "cpu/frame_geometry.hpp"

namespace dacrt {

// A closest-hit frame of an image's rays in bands of whole rows of 8x8 tiles, for `workers`
// workers: where each band starts, then the end. As many bands as rayBatches gives for batches
// of passBatchRays' size, as a multiple of the workers, in tile rows (at most one a row);
// each band as near an equal share of tileRowWork as whole rows allow, equal rows where that
// is empty. Empty where the frame is no such image, a worker is alone, or one band would hold
// it.
std::vector<std::uint32_t> imageBands(const FrameGeometry& geometry, unsigned workers);

// The bands' edges between one another, as planes through a perspective camera's apex: which
// bands' rays can hit a triangle, from its bounds. A band drops a box that lies below its
// bottom edge or above its top edge by more than the view frustum skip's slack (outsideFrustum:
// 2^-12 of the distance to the box's farthest corner, taken here in float32 as 2^-11 of that
// distance's L1 norm, which float32's few roundings of the sum, at most 10 u of it, cannot
// bring under the L2 bound): then every vertex lies outside that edge as outsideFrustum asks,
// and no ray of the band can hit the triangle. The image's own top and bottom edges are the
// view frustum skip's, not tested here.
class BandEdges {
public:
    static constexpr std::size_t kMostBands = 32;  // a band a bit of bandsOf
    // startRows: each band's first pixel row, then the image's rows (frustum.rows); at most
    // kMostBands bands (InternalError beyond).
    BandEdges(const ViewFrustum& frustum, const std::vector<std::uint32_t>& startRows);
    // Bit b set: a ray of band b may hit a triangle within these bounds.
    std::uint32_t bandsOf(const Bounds& b) const {
        const glm::vec3 lo = b.lo - apex_, hi = b.hi - apex_;
        const glm::vec3 far = glm::max(glm::abs(lo), glm::abs(hi));
        const float slack = 0x1p-11f * (far.x + far.y + far.z);
        std::uint32_t mask = edges_ + 1 == kMostBands ? ~0u : (1u << (edges_ + 1)) - 1u;
        for (std::size_t k = 0; k < edges_; ++k) {
            const glm::vec3 atLo = up_[k] * lo, atHi = up_[k] * hi;
            // The largest and smallest n . (corner - apex) over the box's corners: no vertex
            // lies farther towards band k, or towards band k + 1.
            const glm::vec3 most = glm::max(atLo, atHi), least = glm::min(atLo, atHi);
            if (most.x + most.y + most.z < -slack) mask &= ~(1u << k);             // below band k
            if (least.x + least.y + least.z > slack) mask &= ~(1u << (k + 1));     // above band k + 1
        }
        return mask;
    }

private:
    glm::vec3 apex_;
    // up_[k]: the edge between bands k and k + 1, its normal towards band k.
    std::array<glm::vec3, kMostBands - 1> up_{};
    std::size_t edges_ = 0;
};

// For each band (imageBands' starts, in rays, then the end), the traced triangles its rays can
// reach (BandEdges), ascending: one pass over the traced triangles' bounds in chunks on the
// pool, then the bands' lists. Every traced triangle in each band where the frame has no view
// frustum of its rows or the bands are more than BandEdges::kMostBands.
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
