#include "gpu/ray_cost_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace dacrt::gpu {

namespace {

// A plane one unit in front of the shared origin along the region's mean ray direction, with
// a grid of cells over the rectangle its rays cross. Points are projected onto it through the
// origin; a triangle's bounds cover the cells of their corners' projected rectangle.
struct ViewGrid {
    glm::vec3 origin{}, forward{}, right{}, up{};
    glm::vec2 low{};
    glm::vec2 cell{1.0f};
    std::uint32_t width = 1, height = 1;
    std::vector<std::int32_t> cover;  // per cell; a difference array until countCover

    std::optional<glm::vec2> project(const glm::vec3& offset) const {
        const float ahead = glm::dot(offset, forward);
        if (!(ahead > 0.0f)) return std::nullopt;
        return glm::vec2(glm::dot(offset, right), glm::dot(offset, up)) / ahead;
    }
    std::uint32_t column(float x) const { return std::uint32_t(std::clamp((x - low.x) / cell.x, 0.0f, float(width - 1))); }
    std::uint32_t row(float y) const { return std::uint32_t(std::clamp((y - low.y) / cell.y, 0.0f, float(height - 1))); }
};

// Cells of about one ray each, at most kMostCells a side.
constexpr float kMostCells = 1024.0f;

std::optional<ViewGrid> makeViewGrid(const FrameGeometry& g, const std::uint32_t* ids, std::uint32_t count) {
    ViewGrid grid;
    grid.origin = g.rayOrigin;
    glm::vec3 sum(0.0f);
    for (std::uint32_t i = 0; i < count; ++i) sum += glm::normalize((*g.rays)[ids[i]].dir);
    if (!(glm::length(sum) > 0.0f)) return std::nullopt;
    grid.forward = glm::normalize(sum);
    const glm::vec3 side = std::abs(grid.forward.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    grid.right = glm::normalize(glm::cross(grid.forward, side));
    grid.up = glm::cross(grid.right, grid.forward);
    glm::vec2 low(INFINITY), high(-INFINITY);
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::optional<glm::vec2> p = grid.project((*g.rays)[ids[i]].dir);
        if (!p) return std::nullopt;
        low = glm::min(low, *p);
        high = glm::max(high, *p);
    }
    const glm::vec2 extent = glm::max(high - low, glm::vec2(1e-12f));
    const float aspect = extent.x / extent.y;
    grid.width = std::uint32_t(std::clamp(std::round(std::sqrt(float(count) * aspect)), 1.0f, kMostCells));
    grid.height = std::uint32_t(std::clamp(std::round(float(count) / float(grid.width)), 1.0f, kMostCells));
    grid.low = low;
    grid.cell = extent / glm::vec2(grid.width, grid.height);
    grid.cover.assign(std::size_t(grid.width + 1) * (grid.height + 1), 0);
    return grid;
}

// One triangle's bounds: +1 on the cells of their projected rectangle (a difference array). Bounds
// reaching behind the origin's plane may cover any direction: every cell.
void addBounds(ViewGrid& grid, const Bounds& b) {
    glm::vec2 low(INFINITY), high(-INFINITY);
    bool behind = false;
    for (int corner = 0; corner < 8 && !behind; ++corner) {
        const glm::vec3 c(corner & 1 ? b.hi.x : b.lo.x, corner & 2 ? b.hi.y : b.lo.y, corner & 4 ? b.hi.z : b.lo.z);
        const std::optional<glm::vec2> p = grid.project(c - grid.origin);
        behind = !p;
        if (p) low = glm::min(low, *p), high = glm::max(high, *p);
    }
    const glm::vec2 gridHigh = grid.low + grid.cell * glm::vec2(grid.width, grid.height);
    if (!behind && (high.x < grid.low.x || high.y < grid.low.y || low.x > gridHigh.x || low.y > gridHigh.y)) return;
    const std::uint32_t x0 = behind ? 0 : grid.column(low.x), x1 = behind ? grid.width - 1 : grid.column(high.x);
    const std::uint32_t y0 = behind ? 0 : grid.row(low.y), y1 = behind ? grid.height - 1 : grid.row(high.y);
    const std::size_t stride = grid.width + 1;
    grid.cover[y0 * stride + x0] += 1;
    grid.cover[y0 * stride + x1 + 1] -= 1;
    grid.cover[(y1 + 1) * stride + x0] -= 1;
    grid.cover[(y1 + 1) * stride + x1 + 1] += 1;
}

void countCover(ViewGrid& grid) {
    const std::size_t stride = grid.width + 1;
    for (std::uint32_t y = 0; y <= grid.height; ++y)
        for (std::uint32_t x = 1; x <= grid.width; ++x) grid.cover[y * stride + x] += grid.cover[y * stride + x - 1];
    for (std::uint32_t y = 1; y <= grid.height; ++y)
        for (std::uint32_t x = 0; x <= grid.width; ++x) grid.cover[y * stride + x] += grid.cover[(y - 1) * stride + x];
}

void estimateRegion(const FrameGeometry& g, const Division& d, const Region& r, std::uint32_t* costs) {
    const std::uint32_t count = r.rayEnd - r.rayBegin;
    std::optional<ViewGrid> grid = makeViewGrid(g, d.rayIds.data() + r.rayBegin, count);
    if (!grid) {
        std::fill(costs, costs + count, 1u);
        return;
    }
    for (std::uint32_t t = r.triBegin; t < r.triEnd; ++t) addBounds(*grid, (*g.triangleBounds)[d.triIds[t]]);
    countCover(*grid);
    for (std::uint32_t i = 0; i < count; ++i) {
        const glm::vec2 p = *grid->project((*g.rays)[d.rayIds[r.rayBegin + i]].dir);
        costs[i] = std::uint32_t(grid->cover[grid->row(p.y) * std::size_t(grid->width + 1) + grid->column(p.x)]);
    }
}

}  // namespace

std::vector<std::uint32_t> estimateStep1RayCosts(const FrameGeometry& geometry, const Division& division,
                                                 ThreadPool& pool) {
    if (!geometry.raysShareStart) return {};
    std::vector<std::uint32_t> costs(division.rayIds.size(), 0);
    pool.parallelFor(division.regions.size(), [&](std::size_t k, unsigned) {
        const Region& r = division.regions[k];
        if (r.rayEnd > r.rayBegin) estimateRegion(geometry, division, r, costs.data() + r.rayBegin);
    });
    return costs;
}

}  // namespace dacrt::gpu
