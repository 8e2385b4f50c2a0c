#include "cpu/image_bands.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include "core/errors.hpp"
#include "cpu/predicates.hpp"
#include "cpu/ray_grouping.hpp"
#include "cpu/ray_packet.hpp"
#include "cpu/simd_kernels.hpp"
#include "cpu/triangle_skips.hpp"

namespace dacrt {
namespace {

// Enough for a row's share to within a few per cent on 60 rows of tiles (640x480), and few
// enough that the sample costs a small part of a band's own pass over the triangles.
constexpr std::size_t kSampledTriangles = 8192;
// Rays of a row tested against the scene box: the share of the row's rays the DACRT works on
// (those that miss the box end at its first filter).
constexpr std::uint32_t kSampledRaysPerRow = 16;
// What a ray that reaches the scene box weighs against a triangle: from outside the box, a
// twentieth (packets filter the rays 64 at a time down the tree, and most of the rays that reach
// the box of a model, the Bunny or the Dragon, miss the model and leave the tree early); from
// inside, one (every ray meets the scene, a room's walls, and pays its leaf tests, so a scene of
// few triangles seen from inside is cut in nearly equal rows). Of 1, 0.25, 0.1, 0.05 and 0.02 for
// the rays from outside, a twentieth left the Bunny's bands nearest to equal times; the
// Dragon's triangles outweigh its rays at any of them (docs/benchmarks.md, "Image bands of
// equal work").
constexpr double kRayWorkFromOutside = 0.05, kRayWorkFromInside = 1.0;

std::uint32_t imageRows(const FrameGeometry& g) { return std::uint32_t(g.rays->size() / g.imageWidth); }
std::uint32_t tileRows(const FrameGeometry& g) { return (imageRows(g) + kPacketTile - 1) / kPacketTile; }

// The frame's view frustum where it is the pyramid of these rays' rows: the camera's image,
// its rays from the frustum's apex.
const ViewFrustum* rowsOfRays(const FrameGeometry& g) {
    return g.frustum && g.imageWidth && g.frustum->rows > 0 && std::uint32_t(g.frustum->rows) == imageRows(g) &&
                   g.raysShareStart && g.rayOrigin == glm::vec3(g.frustum->apex)
               ? &*g.frustum
               : nullptr;
}

}  // namespace

std::vector<double> tileRowWork(const FrameGeometry& g) {
    const ViewFrustum* f = rowsOfRays(g);
    if (!f) return {};
    const std::uint32_t width = g.imageWidth, height = imageRows(g);
    std::vector<double> work(tileRows(g), 0.0);
    // Triangles: each sampled one's bounds centre in the row of tiles it projects into (sy =
    // (1 - 2 row / rows) halfHeight, as PixelRays makes the rows), as stride triangles.
    const std::size_t traced = g.tracedTriangleCount();
    const std::size_t stride = std::max<std::size_t>(1, traced / kSampledTriangles);
    // The samples are far apart in memory: each is asked for kPrefetchAhead samples early.
    constexpr std::size_t kPrefetchAhead = 16;
    for (std::size_t i = 0; i < traced; i += stride) {
        if (i + kPrefetchAhead * stride < traced)
            __builtin_prefetch(&(*g.triangleBounds)[g.tracedTriangle(i + kPrefetchAhead * stride)]);
        const Bounds& b = (*g.triangleBounds)[g.tracedTriangle(i)];
        const glm::dvec3 toCentre = 0.5 * (glm::dvec3(b.lo) + glm::dvec3(b.hi)) - f->apex;
        const double depth = glm::dot(toCentre, f->forward);
        if (!(depth > 0.0)) continue;
        const double row = 0.5 * (1.0 - glm::dot(toCentre, f->up) / (depth * f->halfHeight)) * height;
        if (!(row >= 0.0 && row < double(height))) continue;
        work[std::size_t(row) / kPacketTile] += double(stride);
    }
    // Rays: each row's that reach the scene box, from a sample of its middle pixel row.
    const glm::vec3 eye(f->apex);
    const bool inside = glm::all(glm::greaterThanEqual(eye, g.sceneBox.lo)) && glm::all(glm::lessThanEqual(eye, g.sceneBox.hi));
    const double rayWork = inside ? kRayWorkFromInside : kRayWorkFromOutside;
    for (std::uint32_t r = 0; r < work.size(); ++r) {
        const std::uint32_t y = std::min(height - 1, r * kPacketTile + kPacketTile / 2);
        const std::uint32_t rowRays = (std::min(height, (r + 1) * kPacketTile) - r * kPacketTile) * width;
        std::uint32_t crossing = 0;
        for (std::uint32_t s = 0; s < kSampledRaysPerRow; ++s) {
            const Ray& ray = (*g.rays)[std::size_t(y) * width + (2 * s + 1) * width / (2 * kSampledRaysPerRow)];
            crossing += shared::rayMayCrossCell(ray, g.sceneBox.lo, g.sceneBox.hi, ray.tmax);
        }
        work[r] += rayWork * double(rowRays) * crossing / kSampledRaysPerRow;
    }
    if (!std::any_of(work.begin(), work.end(), [](double w) { return w > 0.0; })) return {};
    return work;
}

std::vector<std::uint32_t> bandsOfEqualWork(const std::vector<double>& rowWork, std::size_t bands) {
    const std::size_t rows = rowWork.size();
    bands = std::min(bands, rows);
    std::vector<double> before(rows + 1, 0.0);  // before[r]: the work of rows [0, r)
    for (std::size_t r = 0; r < rows; ++r) before[r + 1] = before[r] + rowWork[r];
    std::vector<std::uint32_t> starts{0};
    for (std::size_t b = 1; b < bands; ++b) {
        const double target = before[rows] * double(b) / double(bands);
        // The first start whose rows before it reach the target, or the one before it where
        // that is nearer; each band at least one row, and a row left for each band after.
        const std::size_t lowest = starts.back() + 1, highest = rows - (bands - b);
        std::size_t r = std::size_t(std::lower_bound(before.begin() + std::ptrdiff_t(lowest),
                                                     before.begin() + std::ptrdiff_t(highest) + 1, target) -
                                    before.begin());
        r = std::min(r, highest);
        if (r > lowest && target - before[r - 1] < before[r] - target) --r;
        starts.push_back(std::uint32_t(r));
    }
    starts.push_back(std::uint32_t(rows));
    return starts;
}

std::size_t imageBandCount(const FrameGeometry& g, unsigned workers) {
    const std::uint32_t rays = std::uint32_t(g.rays->size());
    if (!g.imageWidth || g.query != HitQuery::Closest || workers < 2 || rays % g.imageWidth != 0) return 0;
    // Whole rows of tiles: a band's packets are the image's own (buildPackets tiles by ray id).
    const std::size_t rows = tileRows(g);
    const std::size_t mostTileRows =
        std::max<std::size_t>(1, passBatchRays(g.triangles->size()) / (std::size_t(g.imageWidth) * kPacketTile));
    const std::size_t bands = std::min<std::size_t>(rayBatches(rows, mostTileRows, workers).size() - 1, rows);
    return bands < 2 ? 0 : bands;
}

std::vector<std::uint32_t> imageBands(const FrameGeometry& g, unsigned workers) {
    const std::size_t bands = imageBandCount(g, workers);
    if (bands == 0) return {};
    const std::uint32_t rays = std::uint32_t(g.rays->size());
    const std::vector<double> work = tileRowWork(g);
    std::vector<std::uint32_t> starts = bandsOfEqualWork(work.empty() ? std::vector<double>(tileRows(g), 1.0) : work, bands);
    for (std::uint32_t& s : starts) s = std::min(rays, s * kPacketTile * g.imageWidth);
    return starts;
}

BandEdges::BandEdges(const ViewFrustum& frustum, const std::vector<std::uint32_t>& startRows)
    : apex_(glm::vec3(frustum.apex)) {
    // rowsFrustum's bottom plane of the rows above each inner start is that start's edge.
    for (std::size_t k = 1; k + 1 < startRows.size(); ++k)
        up_.push_back(glm::vec3(rowsFrustum(frustum, 0, int(startRows[k])).inward[2]));
}

void BandEdges::bandsOfEach(const Bounds* bounds, const std::uint32_t* ids, std::uint32_t count, std::uint32_t* first,
                            std::uint32_t* last) const {
    simd::bandsOfBounds(bounds, ids, count, apex_, up_.data(), std::uint32_t(up_.size()), first, last);
}

std::vector<std::vector<std::uint32_t>> bandTriangleIds(const FrameGeometry& g, const std::vector<std::uint32_t>& bands,
                                                        ThreadPool& pool) {
    const std::size_t bandCount = bands.size() - 1, traced = g.tracedTriangleCount();
    std::vector<std::vector<std::uint32_t>> ids(bandCount);
    const ViewFrustum* f = rowsOfRays(g);
    if (!f) {
        for (std::vector<std::uint32_t>& band : ids) fillTracedTriangleIds(g, band, &pool);
        return ids;
    }
    std::vector<std::uint32_t> startRows;
    for (std::uint32_t start : bands) {
        // A band's rows are whole: a partial row would lie beyond the band's bottom edge.
        if (start % g.imageWidth != 0)
            throw InternalError("bandTriangleIds: band start " + std::to_string(start) + " inside a row of " +
                                std::to_string(g.imageWidth) + " rays");
        startRows.push_back(start / g.imageWidth);
    }
    const BandEdges edges(*f, startRows);
    // Each traced triangle's bands, and how many each chunk gives each band.
    const std::size_t chunks = (traced + kFrameScanChunk - 1) / kFrameScanChunk;
    std::vector<std::uint32_t> firstBand(traced), lastBand(traced);
    std::vector<std::uint32_t> counts(chunks * bandCount, 0);
    const std::uint32_t* tracedIds = g.tracedTriangles ? g.tracedTriangles->data() : nullptr;
    forEachChunk(traced, kFrameScanChunk, &pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
        edges.bandsOfEach(tracedIds ? g.triangleBounds->data() : g.triangleBounds->data() + begin,
                          tracedIds ? tracedIds + begin : nullptr, std::uint32_t(end - begin), &firstBand[begin],
                          &lastBand[begin]);
        // Counted locally: neighbouring chunks' counts share cache lines.
        std::vector<std::uint32_t> count(bandCount, 0);
        for (std::size_t i = begin; i < end; ++i)
            for (std::uint32_t b = firstBand[i]; b <= lastBand[i]; ++b) ++count[b];
        std::copy(count.begin(), count.end(), &counts[c * bandCount]);
    });
    // Chunk c's triangles of band b go after those of the chunks before it.
    std::vector<std::size_t> offset(chunks * bandCount);
    for (std::size_t b = 0; b < bandCount; ++b) {
        std::size_t total = 0;
        for (std::size_t c = 0; c < chunks; ++c) offset[c * bandCount + b] = total, total += counts[c * bandCount + b];
        ids[b].resize(total);
    }
    forEachChunk(traced, kFrameScanChunk, &pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
        std::vector<std::size_t> next(&offset[c * bandCount], &offset[c * bandCount] + bandCount);
        for (std::size_t i = begin; i < end; ++i)
            for (std::uint32_t b = firstBand[i]; b <= lastBand[i]; ++b) ids[b][next[b]++] = g.tracedTriangle(i);
    });
    return ids;
}

}  // namespace dacrt
