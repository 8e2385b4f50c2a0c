#pragma once
// A secondary pass's rays grouped by the octant of their direction before the cpu backends
// trace them (DacrtOptions::rayGrouping): the rays made pixel by pixel go every which way
// (an occlusion pass's cosine hemisphere), so a DACRT node sees mixed direction signs; sorted,
// a node's rays mostly share them, and a group traced on its own shares them all, so that every
// node visits its children front to back for each of its rays (ChildOrder::NearSide).
#include <array>
#include <cstdint>
#include <vector>

#include "core/thread_pool.hpp"
#include "cpu/secondary_rays.hpp"

namespace dacrt {

// Bit a of a ray's octant is set where its direction is negative along axis a (a zero counts
// as positive: it crosses no split, so either order suits it).
constexpr unsigned kOctants = 8;
std::uint32_t directionOctant(const Ray& ray);

// Buffers the grouping writes into, kept from pass to pass by their owner: fresh pages cost
// a fault each on a VM, more than the grouping's copy itself.
struct GroupingBuffers {
    std::vector<Ray> rays;
    std::vector<std::uint32_t> slots;
    std::vector<Ray> group;  // RayGrouping::OctantCalls: the octant being traced
};

// rays.rays and rays.slots reordered together by octant, the order within an octant kept
// (a stable counting sort, in parallel chunks): hitsPerSlot still puts every hit in its slot.
// The reordered arrays are written into `buffers` and swapped with the rays', so that
// `buffers` keeps the arrays the rays were made in for the next pass.
// Returns where each octant's rays begin, and (entry kOctants) where the last one ends.
using OctantStarts = std::array<std::size_t, kOctants + 1>;
OctantStarts groupByOctant(SecondaryRays& rays, GroupingBuffers& buffers, ThreadPool& pool);


// Where each of the equal batches of `rays` rays begins, then `rays`: as few batches of at
// most `most` rays as a multiple of `multipleOf` allows (one batch where they number at most
// `most` and multipleOf is 1).
std::vector<std::size_t> rayBatches(std::size_t rays, std::size_t most, std::size_t multipleOf = 1);

// The most rays a batch traced as one sequential DACRT holds (a pass's --ray-grouping batches,
// a gpu pass's ray groups on a CPU device, the cpu backend's image bands): kPassBatchRays, or
// kPassBatchRaysPerTriangle per triangle of the scene where that is more, so that a batch's
// rays outnumber what its own filtering of every triangle costs.
std::size_t passBatchRays(std::size_t triangles);

}  // namespace dacrt
