#include "cpu/ray_grouping.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include "core/mapped_memory.hpp"
#include "cpu/options.hpp"

namespace dacrt {

std::uint32_t directionOctant(const Ray& ray) {
    return std::uint32_t(ray.dir.x < 0.0f) | std::uint32_t(ray.dir.y < 0.0f) << 1 | std::uint32_t(ray.dir.z < 0.0f) << 2;
}

OctantStarts groupByOctant(SecondaryRays& rays, GroupingBuffers& buffers, ThreadPool& pool) {
    const std::size_t n = rays.rays.size();
    // Each chunk counts its octants, then writes its rays after the earlier chunks' of the same
    // octant: stable, and every chunk's writes are its own.
    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(4 * pool.size(), n / 4096));
    std::vector<OctantStarts> at(chunks, OctantStarts{});
    auto chunkBegin = [&](std::size_t c) { return n * c / chunks; };
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        for (std::size_t i = chunkBegin(c); i < chunkBegin(c + 1); ++i) ++at[c][directionOctant(rays.rays[i])];
    });
    OctantStarts starts{};
    std::size_t next = 0;
    for (unsigned o = 0; o < kOctants; ++o) {
        starts[o] = next;
        for (OctantStarts& counts : at) {
            const std::size_t count = counts[o];
            counts[o] = next;
            next += count;
        }
    }
    starts[kOctants] = next;
    std::vector<Ray>& grouped = buffers.rays;
    std::vector<std::uint32_t>& slots = buffers.slots;
    reserveMapped(grouped, n);
    reserveMapped(slots, n);
    grouped.resize(n);
    slots.resize(n);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        for (std::size_t i = chunkBegin(c); i < chunkBegin(c + 1); ++i) {
            const std::size_t to = at[c][directionOctant(rays.rays[i])]++;
            grouped[to] = rays.rays[i];
            slots[to] = rays.slots[i];
        }
    });
    std::swap(rays.rays, grouped);
    std::swap(rays.slots, slots);
    return starts;
}

std::size_t passBatchRays(std::size_t triangles) {
    return std::max<std::size_t>(kPassBatchRays, std::size_t(kPassBatchRaysPerTriangle) * triangles);
}

std::vector<std::size_t> rayBatches(std::size_t rays, std::size_t most, std::size_t multipleOf) {
    const std::size_t share = std::max<std::size_t>(1, multipleOf);
    const std::size_t batches = (std::max<std::size_t>(1, (rays + most - 1) / most) + share - 1) / share * share;
    std::vector<std::size_t> starts(batches + 1);
    for (std::size_t b = 0; b <= batches; ++b) starts[b] = rays * b / batches;
    return starts;
}

}  // namespace dacrt
