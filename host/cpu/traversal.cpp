#include "cpu/traversal.hpp"

#include <algorithm>
#include <optional>
#include <utility>

#include "core/mapped_memory.hpp"
#include "cpu/option_predicates.hpp"

namespace dacrt {
namespace {

// What the ray filter may broadcast from the first ray (simd::SharedRayFields).
simd::SharedRayFields sharedRayFieldsOf(const FrameGeometry& g, const TraversalBuffers& buffers) {
    if (g.raysShareStart) return simd::SharedRayFields::Start;
    if (g.query == HitQuery::Any)
        return buffers.raysShareSegment ? simd::SharedRayFields::Segment : simd::SharedRayFields::OwnSegment;
    return simd::SharedRayFields::None;
}

}  // namespace

std::uint64_t packetTiles(const FrameGeometry& g) {
    if (!g.imageWidth || !g.raysShareStart) return 0;
    const std::uint64_t height = g.rays->size() / g.imageWidth;
    return ((g.imageWidth + kPacketTile - 1) / kPacketTile) * ((height + kPacketTile - 1) / kPacketTile);
}

bool usesSimd(const FrameGeometry& g, const DacrtOptions& options) {
    return usesSimd(g.rays->size(), g.triangles->size(), options);
}

bool usesSimd(std::uint64_t rays, std::uint64_t triangles, const DacrtOptions& options) {
    return options.exactDefaults() && rays <= simd::kMaxRays && triangles <= simd::kMaxTriangles;
}

bool usesPackets(const FrameGeometry& g, const DacrtOptions& options) {
    return options.packets && usesSimd(g, options) && packetTiles(g) > 0;
}

namespace {

// One worker's packet arrays, element by element: what the plan counts and the storage
// allocates (plus one finished flag per ray of the frame, shared).
struct PacketArrayCounts {
    std::uint64_t rayIds = 0;      // packetRays, and flushRays as many
    std::uint64_t packets = 0;     // packets, and packetIds as many
    std::uint64_t tileStarts = 0;  // tileCounts
};

PacketArrayCounts packetArrayCounts(const FrameGeometry& g, const DacrtOptions& options, std::uint64_t scratchIds) {
    if (!usesPackets(g, options)) return {};
    const std::uint64_t tiles = packetTiles(g);
    return {scratchIds, tiles, tiles + 1};
}

}  // namespace

void planPacketBuffers(const FrameGeometry& g, const DacrtOptions& options, std::uint64_t scratchIds, unsigned workers,
                       MemoryPlan& plan) {
    const PacketArrayCounts c = packetArrayCounts(g, options, scratchIds);
    if (!c.packets) return;
    plan.add("packet rays and flushed rays (per thread)", 2 * c.rayIds * sizeof(std::uint32_t) * workers);
    plan.add("packets (per thread)",
             (c.packets * (sizeof(RayPacket) + sizeof(std::uint32_t)) + c.tileStarts * sizeof(std::uint32_t)) * workers);
    plan.add("ray finished flags", g.rays->size() * sizeof(std::uint8_t));
}

PacketStorage::PacketStorage(const FrameGeometry& g, const DacrtOptions& options, std::uint64_t ids, unsigned workers)
    : scratchIds(ids), tiles(packetArrayCounts(g, options, ids).packets) {
    if (!tiles) return;
    const PacketArrayCounts c = packetArrayCounts(g, options, ids);
    resizeMapped(packetRays, c.rayIds * workers);
    resizeMapped(flushRays, c.rayIds * workers);
    resizeMapped(packets, c.packets * workers);
    resizeMapped(packetIds, c.packets * workers);
    resizeMapped(tileCounts, c.tileStarts * workers);
    if (rayDone.capacity() < g.rays->size()) reserveMapped(rayDone, g.rays->size());
    rayDone.assign(g.rays->size(), 0);
}

PacketBuffers PacketStorage::forWorker(unsigned w) {
    if (!tiles) return {};
    return {packetRays.data() + w * scratchIds, flushRays.data() + w * scratchIds, packets.data() + w * tiles,
            packetIds.data() + w * tiles, tileCounts.data() + w * (tiles + 1), rayDone.data()};
}

std::uint64_t partitionScratchIds(std::uint64_t rayRange, std::uint64_t triRange) {
    return std::max(rayRange, triRange) + simd::kScratchSlack;
}

DacrtTraversal::DacrtTraversal(const FrameGeometry& g, const DacrtOptions& options, const TraversalBuffers& buffers,
                               Counters& counters)
    : rays_(g.rays->data()),
      triangles_(g.triangles->data()),
      triangleBounds_(g.triangleBounds->data()),
      triangleFaces_(g.triangleFaces()),
      order_(g.order),
      orderPoint_(g.nearSide),
      anyHit_(g.query == HitQuery::Any),
      triangleOrderFree_(options.split == SplitMethod::SpatialMedian && options.splitCost == SplitCost::Limits &&
                         options.triangleFilter == TriangleFilter::Bounds),
      margin_(g.margin),
      options_(options.resolvedFor(Backend::Cpu)),
      hits_(buffers.hits),
      rayIds_(buffers.rayIds),
      triIds_(buffers.triIds),
      scratch_(buffers.scratch),
      sharedRayFields_(sharedRayFieldsOf(g, buffers)),
      simd_(scratch_ && usesSimd(g, options_)),
      packets_(simd_ && buffers.packets.packetRays && usesPackets(g, options_)),
      packet_(buffers.packets),
      imageWidth_(g.imageWidth),
      tiles_(std::uint32_t(packetTiles(g))),
      counters_(counters) {}

std::uint32_t DacrtTraversal::trace(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd,
                                    std::uint32_t triBegin, std::uint32_t triEnd, const RetireRule& retire) {
    const std::uint32_t crossing = filterRays(widenedBox(box, margin_), terminated, rayEnd);
    if (packets_)
        tracePackets(box, terminated, crossing, triBegin, triEnd);
    else
        node(box, terminated, crossing, triBegin, triEnd, 0, 0);
    if (retire.axis < 0) return crossing;
    const Box cell = widenedBox(box, margin_);
    for (std::uint32_t k = terminated; k < rayEnd; ++k) {
        const std::uint32_t id = rayIds_[k];
        const float d = rays_[id].dir[retire.axis];
        const bool done = retire.direction == 0
                              ? d == 0.0f
                              : (retire.direction > 0 ? d > 0.0f : d < 0.0f) &&
                                    !shared::rayMayCrossCell(rays_[id], cell.lo, cell.hi, hits_[id].t);
        if (done) {
            std::swap(rayIds_[k], rayIds_[terminated]);
            ++terminated;
            ++counters_.raysFinishedWithoutHit;
        }
    }
    return crossing;
}

[[gnu::flatten]] std::uint32_t DacrtTraversal::filterRays(const Box& cell, std::uint32_t begin, std::uint32_t end) {
    counters_.rayBoxTests += end - begin;
    if (simd_) return begin + simd::partitionRaysMayCrossCell(rays_, hits_, rayIds_ + begin, end - begin, cell, sharedRayFields_,
                                                            scratch_);
    std::uint32_t* first = std::partition(rayIds_ + begin, rayIds_ + end, [&](std::uint32_t id) {
        return shared::rayMayCrossCell(rays_[id], cell.lo, cell.hi, hits_[id].t);
    });
    return std::uint32_t(first - rayIds_);
}

std::uint32_t DacrtTraversal::filterRaysMoving(const Box& cell, std::uint32_t begin, std::uint32_t end, int axis,
                                               int moving, std::uint32_t certainFrom) {
    if (moving == 0) {
        // [certainFrom, end) pass untested: moved behind the tested ones that pass.
        const std::uint32_t passed = filterRays(cell, begin, certainFrom);
        std::rotate(rayIds_ + passed, rayIds_ + certainFrom, rayIds_ + end);
        return passed + (end - certainFrom);
    }
    std::uint32_t* moved = std::partition(rayIds_ + begin, rayIds_ + end, [&](std::uint32_t id) {
        return (rays_[id].dir[axis] < 0.0f) == (moving < 0);
    });
    return filterRays(cell, begin, std::uint32_t(moved - rayIds_));
}

std::uint32_t DacrtTraversal::filterTriangles(const Box& child, const Box& cell, std::uint32_t begin,
                                              std::uint32_t end, int axis, bool lowChild) {
    std::uint32_t* first = triIds_ + begin;
    switch (options_.triangleFilter) {
        case TriangleFilter::Bounds:
            return partitionTrianglesByBounds(cell, begin, end, axis, lowChild, simd::FaceSide::Reaching);
        case TriangleFilter::Sat:
            first = std::partition(triIds_ + begin, triIds_ + end, [&](std::uint32_t id) {
                return triangleOverlapsBoxSat(triangles_[id], triangleBounds_[id], cell.lo, cell.hi);
            });
            break;
        case TriangleFilter::Mora:
            // The unwidened child: Mora's test has no rounding margin (that is its price).
            first = std::partition(triIds_ + begin, triIds_ + end, [&](std::uint32_t id) {
                return triangleOverlapsBoxMora(triangles_[id], triangleBounds_[id], child.lo, child.hi, end - begin);
            });
            break;
    }
    return std::uint32_t(first - triIds_);
}

std::uint32_t DacrtTraversal::filterTrianglesAfterSibling(const Box& cell, std::uint32_t begin, std::uint32_t siblingEnd,
                                                          int axis, bool lowChild) {
    return partitionTrianglesByBounds(cell, begin, siblingEnd, axis, lowChild, simd::FaceSide::Beyond);
}

std::uint32_t DacrtTraversal::partitionTrianglesByBounds(const Box& cell, std::uint32_t begin, std::uint32_t end, int axis,
                                                         bool lowChild, simd::FaceSide keep) {
    if (simd_)
        return begin + simd::partitionTrianglesOnFace(triangleFaces_, triIds_ + begin, end - begin, axis, lowChild,
                                                      lowChild ? cell.hi[axis] : cell.lo[axis], scratch_, keep);
    const bool reaching = keep == simd::FaceSide::Reaching;
    std::uint32_t* first = std::partition(triIds_ + begin, triIds_ + end, [&](std::uint32_t id) {
        const Bounds& b = triangleBounds_[id];
        return shared::boundsOverlap(b.lo, b.hi, cell.lo, cell.hi) == reaching;
    });
    return std::uint32_t(first - triIds_);
}

float DacrtTraversal::splitPosition(const Box& box, int axis, std::uint32_t triBegin, std::uint32_t triEnd) const {
    const float mid = spatialMedian(box, axis);
    if (options_.split == SplitMethod::SpatialMedian) return mid;
    // Mora's sampled mean: every 50th triangle centre once the set is large, all of them below.
    const std::uint32_t count = triEnd - triBegin;
    const std::uint32_t stride = options_.split == SplitMethod::SampledMean && count > 500 ? 50 : 1;
    double sum = 0.0;
    std::uint32_t samples = 0;
    for (std::uint32_t i = triBegin; i < triEnd; i += stride, ++samples) {
        const Bounds& b = triangleBounds_[triIds_[i]];
        sum += 0.5 * (double(b.lo[axis]) + double(b.hi[axis]));
    }
    const float s = float(sum / double(std::max(samples, 1u)));
    return s > box.lo[axis] && s < box.hi[axis] ? s : mid;
}

// The split both recursions share (node over rays, nodePackets over packets): the longest
// axis at the split position (or, under SplitCost::RaySampling, the axis and position the
// sampled estimate finds cheapest), then the children front to back, each with its items and
// triangles filtered from the node's (a second of two children, its triangles from the first's:
// filterTrianglesAfterSibling). With a common order (ChildOrder::NearSide) or
// for any hit (where order changes no result) every item visits the near child, then the far
// one; with ChildOrder::PerRay the rays moving up visit the low child, then all rays the high
// one, then the rays moving down the low one, so that each ray meets its children in the
// order it crosses them. itemBegin is read again for each visit: a ray recursion moves the
// rays an earlier visit finished before it. False (nothing done) where the node must end here
// instead: fewItems, too few triangles, too deep, stalled, no split inside, or (sampleRays:
// items are rays, under SplitCost::RaySampling) cheaper as a leaf by the sampled estimate.
template <typename FilterItems, typename Descend>
bool DacrtTraversal::splitNode(const Box& box, const std::uint32_t& itemBegin, std::uint32_t itemEnd,
                               std::uint32_t triBegin, std::uint32_t triEnd, std::uint32_t depth,
                               std::uint32_t stalls, bool fewItems, bool sampleRays, FilterItems filterItems,
                               Descend descend) {
    int axis = longestAxis(box);
    float split = splitPosition(box, axis, triBegin, triEnd);
    if (endsAsLeaf(box, axis, split, fewItems, triEnd - triBegin, depth, stalls, options_)) return false;
    if (sampleRays && !sampledSplit(box, axis, itemBegin, itemEnd, triBegin, triEnd, split)) return false;
    Box low = box, high = box;
    low.hi[axis] = split;
    high.lo[axis] = split;
    struct Visit {
        const Box* child;
        int moving;  // the rays that visit it: +1 moving up (or not at all along axis), -1 down, 0 all
    };
    const bool lowFirst = lowChildFirst(order_, orderPoint_, axis, split);
    Visit visits[3] = {{lowFirst ? &low : &high, 0}, {lowFirst ? &high : &low, 0}, {nullptr, 0}};
    if (order_ == ChildOrder::PerRay) {
        visits[0] = {&low, anyHit_ ? 0 : 1};
        visits[1] = {&high, 0};
        visits[2] = {anyHit_ ? nullptr : &low, -1};
    }
    // Where the triangles of the first child filtered end: a second child takes its triangles
    // from the first's range (those reaching past the split) and from behind it (those the
    // first child left), so it filters the first child's triangles only, not the node's.
    std::uint32_t firstChildTris = triBegin;
    const bool twoVisits = visits[2].child == nullptr;
    const bool secondFromFirst = twoVisits && triangleOrderFree_;
    // Where the first child's items end: the node's items behind them, to itemEnd, crossed the
    // node's widened cell but not the first child's, so (with two visits) they cross the second
    // child's, since the two children's widened cells cover the node's. The second visit tests
    // only the first child's items (docs/correctness.md, "The second child's rays"). Packets
    // ignore it: a packet's test may pass a cell none of its rays crosses.
    std::uint32_t firstChildItems = itemEnd;
    for (const Visit& visit : visits) {
        if (!visit.child) break;
        const Box cell = widenedBox(*visit.child, margin_);
        const bool second = twoVisits && &visit == &visits[1];
        const std::uint32_t childItems =
            filterItems(cell, itemBegin, itemEnd, axis, visit.moving, second ? firstChildItems : itemEnd);
        if (&visit == &visits[0]) firstChildItems = childItems;
        if (childItems == itemBegin) continue;
        const bool lowChild = visit.child == &low;
        std::uint32_t childBegin = triBegin, childEnd = triEnd;
        if (secondFromFirst && firstChildTris != triBegin)
            childBegin = filterTrianglesAfterSibling(cell, triBegin, firstChildTris, axis, lowChild);
        else
            childEnd = firstChildTris = filterTriangles(*visit.child, cell, triBegin, triEnd, axis, lowChild);
        const bool stalled = childItems == itemEnd && childBegin == triBegin && childEnd == triEnd;
        descend(*visit.child, childItems, childBegin, childEnd, depth + 1, stalled ? stalls + 1 : 0);
    }
    return true;
}

bool DacrtTraversal::sampledSplit(const Box& box, int& axis, std::uint32_t rayBegin, std::uint32_t rayEnd,
                                  std::uint32_t triBegin, std::uint32_t triEnd, float& split) {
    const SampledNode sampled{rays_,           hits_,           rayIds_ + rayBegin,       rayEnd - rayBegin,
                              triangleBounds_, triIds_ + triBegin, triEnd - triBegin, options_.rayLimit,
                              options_.triLimit};
    const SplitChoice choice = chooseSplitByRaySampling(sampled, box, axis, margin_, split);
    counters_.rayBoxTests += choice.rayBoxTests;
    if (choice.split) {
        axis = choice.axis;
        split = choice.position;
    }
    return choice.split;
}

// Only where the rays outnumber the triangles (kTightBoxRaysPerTriangle): the box costs a pass
// over the triangles' bounds and saves tests of rays. None where the shrunk box would be the cell,
// or empty on an axis (triangles that only reach into the cell's margin). The bounds' minimum and
// maximum are exact, so the scalar path takes them from the same kernel.
std::optional<Box> DacrtTraversal::shrunkBox(const Box& cell, std::uint64_t rays, std::uint32_t triBegin,
                                             std::uint32_t triEnd) {
    if (!options_.tightBoxes || rays < kTightBoxRaysPerTriangle * std::uint64_t(triEnd - triBegin)) return std::nullopt;
    const Box reach =
        widenedBox(simd::boundsOfTriangles(triangleBounds_, triIds_ + triBegin, triEnd - triBegin), margin_);
    Box tight;
    tight.lo = glm::max(cell.lo, reach.lo);
    tight.hi = glm::min(cell.hi, reach.hi);
    if (tight.empty() || (tight.lo == cell.lo && tight.hi == cell.hi)) return std::nullopt;
    ++counters_.tightBoxes;
    return tight;
}

Box DacrtTraversal::tightenedBox(const Box& cell, std::uint32_t& terminated, std::uint32_t& rayEnd,
                                 std::uint32_t triBegin, std::uint32_t triEnd) {
    const std::optional<Box> tight = shrunkBox(cell, rayEnd - terminated, triBegin, triEnd);
    if (!tight) return cell;
    rayEnd = filterRays(widenedBox(*tight, margin_), terminated, rayEnd);
    return *tight;
}

void DacrtTraversal::node(const Box& cell, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                          std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls) {
    if (terminated >= rayEnd || triBegin >= triEnd) return;
    const Box box = tightenedBox(cell, terminated, rayEnd, triBegin, triEnd);
    nodeInBox(box, terminated, rayEnd, triBegin, triEnd, depth, stalls);
}

void DacrtTraversal::nodeInBox(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                               std::uint32_t triEnd, std::uint32_t depth, std::uint32_t stalls) {
    if (terminated >= rayEnd) return;
    const bool split = splitNode(
        box, terminated, rayEnd, triBegin, triEnd, depth, stalls, rayEnd - terminated < options_.rayLimit,
        options_.splitCost == SplitCost::RaySampling, [&](const Box& cell, std::uint32_t begin, std::uint32_t end, int axis, int moving,
                                                           std::uint32_t certainFrom) {
            return filterRaysMoving(cell, begin, end, axis, moving, certainFrom);
        },
        [&](const Box& child, std::uint32_t childRays, std::uint32_t childTriBegin, std::uint32_t childTriEnd,
            std::uint32_t d, std::uint32_t s) { node(child, terminated, childRays, childTriBegin, childTriEnd, d, s); });
    if (!split) leaf(box, terminated, rayEnd, triBegin, triEnd);
}

// The rays of [terminated, crossing) in packets: traced down as packets to nodes with fewer
// than packetFlush of them, one by one below. Finished rays are flagged, and moved before
// `terminated` at the end as node() would have moved them.
void DacrtTraversal::tracePackets(const Box& box, std::uint32_t& terminated, std::uint32_t crossing,
                                  std::uint32_t triBegin, std::uint32_t triEnd) {
    const std::uint32_t packetCount = buildPackets(terminated, crossing);
    nodePackets(box, 0, packetCount, triBegin, triEnd, 0, 0);
    for (std::uint32_t k = terminated; k < crossing; ++k)
        if (packet_.rayDone[rayIds_[k]]) std::swap(rayIds_[k], rayIds_[terminated++]);
}

// A counting sort of the rays by 8x8 tile into packetRays, then each packet's bounds.
std::uint32_t DacrtTraversal::buildPackets(std::uint32_t begin, std::uint32_t end) {
    std::uint32_t* tileEnds = packet_.tileCounts;
    sortRaysByTile(rayIds_ + begin, end - begin, imageWidth_, tiles_, tileEnds, packet_.packetRays);
    std::uint32_t packets = 0, tileBegin = 0;
    for (std::uint32_t t = 0; t < tiles_; tileBegin = tileEnds[t], ++t) {
        if (tileEnds[t] == tileBegin) continue;
        RayPacket& p = packet_.packets[packets];
        p = simd::boundsOfRays(rays_, packet_.packetRays + tileBegin, tileEnds[t] - tileBegin);
        p.begin = tileBegin;
        p.end = tileEnds[t];
        packet_.packetIds[packets] = packets;
        ++packets;
    }
    return packets;
}

std::uint32_t DacrtTraversal::filterPackets(const Box& cell, std::uint32_t begin, std::uint32_t end) {
    counters_.packetBoxTests += end - begin;
    const glm::vec3 origin = rays_[0].origin;  // every ray's (packets need raysShareStart)
    const float tmin = rays_[0].tmin;
    std::uint32_t* first = std::partition(packet_.packetIds + begin, packet_.packetIds + end, [&](std::uint32_t p) {
        return packetMayCrossCell(packet_.packets[p], origin, tmin, cell);
    });
    return std::uint32_t(first - packet_.packetIds);
}

void DacrtTraversal::nodePackets(const Box& nodeCell, std::uint32_t packetBegin, std::uint32_t packetEnd,
                                 std::uint32_t triBegin, std::uint32_t triEnd, std::uint32_t depth,
                                 std::uint32_t stalls) {
    if (packetBegin >= packetEnd || triBegin >= triEnd) return;
    // The packets' rays, finished ones included: what the rule weighs against the triangles.
    std::uint64_t rays = 0;
    for (std::uint32_t i = packetBegin; options_.tightBoxes && i < packetEnd; ++i) {
        const RayPacket& p = packet_.packets[packet_.packetIds[i]];
        rays += p.end - p.begin;
    }
    const std::optional<Box> tight = shrunkBox(nodeCell, rays, triBegin, triEnd);
    if (tight) {
        packetEnd = filterPackets(widenedBox(*tight, margin_), packetBegin, packetEnd);
        if (packetBegin >= packetEnd) return;
    }
    const Box& box = tight ? *tight : nodeCell;
    const bool split = splitNode(
        box, packetBegin, packetEnd, triBegin, triEnd, depth, stalls, packetEnd - packetBegin < options_.packetFlush,
        false, [&](const Box& cell, std::uint32_t begin, std::uint32_t end, int, int, std::uint32_t) {
            return filterPackets(cell, begin, end);
        },
        [&](const Box& child, std::uint32_t childPackets, std::uint32_t childTriBegin, std::uint32_t childTriEnd,
            std::uint32_t d, std::uint32_t s) { nodePackets(child, packetBegin, childPackets, childTriBegin, childTriEnd, d, s); });
    if (!split) flushPackets(box, packetBegin, packetEnd, triBegin, triEnd, depth, stalls);
}

// The node's unfinished rays go on one by one, from its own ray filter down.
void DacrtTraversal::flushPackets(const Box& box, std::uint32_t packetBegin, std::uint32_t packetEnd,
                                  std::uint32_t triBegin, std::uint32_t triEnd, std::uint32_t depth,
                                  std::uint32_t stalls) {
    std::uint32_t count = 0;
    for (std::uint32_t i = packetBegin; i < packetEnd; ++i) {
        const RayPacket& p = packet_.packets[packet_.packetIds[i]];
        // Every id written, the count moved past the unfinished ones only: whether a ray is
        // finished is a coin toss that the branch predictor loses. The slot at the count is
        // inside the buffer: the count is at most the number of ids read before it.
        for (std::uint32_t k = p.begin; k < p.end; ++k) {
            const std::uint32_t id = packet_.packetRays[k];
            packet_.flushRays[count] = id;
            count += packet_.rayDone[id] == 0;
        }
    }
    if (count == 0) return;
    std::uint32_t* const regionRays = rayIds_;
    rayIds_ = packet_.flushRays;
    std::uint32_t terminated = 0;
    const std::uint32_t crossing = filterRays(widenedBox(box, margin_), 0, count);
    // The packet node's box already went through shrunkBox, with at least these rays.
    nodeInBox(box, terminated, crossing, triBegin, triEnd, depth, stalls);
    for (std::uint32_t k = 0; k < terminated; ++k) packet_.rayDone[rayIds_[k]] = 1;
    rayIds_ = regionRays;
}

void DacrtTraversal::leaf(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd, std::uint32_t triBegin,
                          std::uint32_t triEnd) {
    ++counters_.leaves;
    counters_.rayTriangleTests += std::uint64_t(rayEnd - terminated) * (triEnd - triBegin);
    auto same = [](const Ray& ray) -> const Ray& { return ray; };
    if (simd_)
        leafSimd(box, terminated, rayEnd, triBegin, triEnd);
    else if (options_.precision == Precision::F64)
        leafWith(box, terminated, rayEnd, triBegin, triEnd, toF64, testTriangleF64);
    else if (options_.intersector == Intersector::MollerTrumbore)
        leafWith(box, terminated, rayEnd, triBegin, triEnd, same, testTriangleMollerTrumbore);
    else
        leafWith(box, terminated, rayEnd, triBegin, triEnd, same, testTriangle);
}

template <typename PrepareRay, typename TestTriangle>
[[gnu::flatten]] void DacrtTraversal::leafWith(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd,
                                               std::uint32_t triBegin, std::uint32_t triEnd, PrepareRay prepare,
                                               TestTriangle test) {
    for (std::uint32_t k = terminated; k < rayEnd; ++k) {
        const std::uint32_t rayId = rayIds_[k];
        const Ray& ray = rays_[rayId];
        const auto& prepared = prepare(ray);
        Hit best = hits_[rayId];
        for (std::uint32_t j = triBegin; j < triEnd; ++j) {
            const std::uint32_t prim = triIds_[j];
            test(prepared, triangles_[prim], prim, best);
        }
        hits_[rayId] = best;
    }
    endRaysHitInBox(box, terminated, rayEnd);
}

void DacrtTraversal::leafSimd(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd,
                              std::uint32_t triBegin, std::uint32_t triEnd) {
    const bool groups = sharedRayFields_ == simd::SharedRayFields::Start;
    const Box cell = widenedBox(box, margin_);
    for (std::uint32_t j = triBegin; j < triEnd; j += simd::kLeafBatch) {
        simd::gatherLeafTriangles(triangles_, triIds_ + j, std::min(triEnd - j, simd::kLeafBatch), batch_);
        if (groups)
            counters_.rayTriangleTestsSkipped += simd::intersectBatchInGroups(
                rays_, hits_, rayIds_ + terminated, rayEnd - terminated, batch_, 2.0f * margin_);
        else
            counters_.rayTriangleTestsSkipped += simd::intersectBatchInSegmentGroups(
                rays_, hits_, rayIds_ + terminated, rayEnd - terminated, batch_, cell, 2.0f * margin_, anyHit_);
    }
    endRaysHitInBox(box, terminated, rayEnd);
}

void DacrtTraversal::endRaysHitInBox(const Box& box, std::uint32_t& terminated, std::uint32_t rayEnd) {
    if (simd_) {
        terminated += simd::endRaysHitInBox(rays_, hits_, rayIds_ + terminated, rayEnd - terminated, box, anyHit_);
        return;
    }
    for (std::uint32_t k = terminated; k < rayEnd; ++k) {
        const std::uint32_t rayId = rayIds_[k];
        if (hits_[rayId].prim != kMissPrim &&
            (anyHit_ || shared::hitEndsInBox(rays_[rayId], box.lo, box.hi, hits_[rayId].t))) {
            std::swap(rayIds_[k], rayIds_[terminated]);
            ++terminated;
        }
    }
}

void testTriangleMollerTrumbore(const Ray& ray, const Triangle& tri, std::uint32_t prim, Hit& best) {
    const shared::TriangleHit h = intersectMollerTrumbore(ray, tri.v0, tri.v1, tri.v2, tri.cullBackFace != 0u);
    if (h.hit && h.t > ray.tmin && shared::hitPrecedes(h.t, prim, best.t, best.prim)) best = Hit{h.t, prim, h.u, h.v};
}

void testTriangleF64(const RayF64& ray, const Triangle& tri, std::uint32_t prim, Hit& best) {
    // The float64 hit is rounded to float32 for the tie rule and the result: hits closer than
    // half a float32 ulp in depth become ties (lowest id), which the benchmark counts as near ties.
    const TriangleHitF64 h = intersectWatertightF64(ray, tri.v0, tri.v1, tri.v2, tri.cullBackFace != 0u);
    if (!h.hit || !(h.t > ray.tmin)) return;
    const float t = float(h.t);
    if (shared::hitPrecedes(t, prim, best.t, best.prim)) best = Hit{t, prim, float(h.u), float(h.v)};
}

}  // namespace dacrt
