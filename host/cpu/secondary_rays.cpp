#include "cpu/secondary_rays.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"

namespace dacrt {

ShadowLight shadowLightOf(const Light& light) {
    ShadowLight s{};
    s.type = light.type == LightType::Point ? shared::kLightPoint
                                            : (light.type == LightType::Spot ? shared::kLightSpot : shared::kLightDirectional);
    s.position = glm::vec3(light.position);
    // Components below 2^-40 are flushed, as the surface normals' are: no product with one is
    // subnormal, which a device may flush and the host would not.
    s.direction = glm::vec3(glm::normalize(light.direction));
    for (int a = 0; a < 3; ++a)
        if (std::abs(s.direction[a]) < 0x1p-40f) s.direction[a] = 0.0f;
    s.range = light.range;
    const double cosOuter = std::cos(light.outerConeAngle);
    s.cosOuterSquared = light.type == LightType::Spot ? float(cosOuter * cosOuter) : 0.0f;
    return s;
}

std::uint32_t occlusionStream(const SecondaryPass& pass, std::uint32_t primary, std::uint32_t k) {
    const std::uint32_t perHit = pass.samplesPerHit ? pass.samplesPerHit : pass.raysPerHit;
    return primary * perHit + pass.firstSample + k;
}

DacrtOptions passDacrtOptions(const DacrtOptions& options) {
    DacrtOptions o = options;
    if (o.triLimit == 0 && o.exactDefaults()) o.triLimit = kCpuSimdSecondaryTriangleLimit;
    return o;
}

float passSegmentEnd(const SecondaryPass& pass) {
    return pass.kind == shared::kPassShadow ? shared::shadowSegmentEnd(pass.light) : pass.occlusionDistance;
}

std::uint64_t secondarySlots(const SecondaryPass& pass, std::uint64_t primaryRays) {
    const std::uint64_t slots = primaryRays * pass.raysPerHit;
    const std::uint64_t streams = primaryRays * std::max(pass.raysPerHit, pass.samplesPerHit);
    if (pass.raysPerHit == 0 || slots > kMaxSecondarySlots || streams > kMaxSecondarySlots)
        throw InputError(pass.name + ": " + std::to_string(primaryRays) + " pixels x " + std::to_string(pass.raysPerHit) +
                         " rays per hit is more than the " + std::to_string(kMaxSecondarySlots) +
                         " rays a pass can hold (32-bit slots); lower --size or --ao");
    return slots;
}

PassRayCounts passRayCounts(const SecondaryPass& pass, const std::vector<Hit>& primaryHits, ThreadPool& pool) {
    PassRayCounts counts;
    counts.primaryRays = primaryHits.size();
    counts.chunks = std::max<std::size_t>(1, std::min<std::size_t>(256, primaryHits.size() / 1024 + 1));
    counts.atMost.assign(counts.chunks + 1, 0);
    pool.parallelFor(counts.chunks, [&](std::size_t c, unsigned) {
        std::size_t hits = 0;
        for (std::size_t i = counts.chunkBegin(c), end = counts.chunkBegin(c + 1); i < end; ++i)
            hits += hitSendsRays(primaryHits[i]);
        counts.atMost[c + 1] = hits * pass.raysPerHit;
    });
    for (std::size_t c = 0; c < counts.chunks; ++c) counts.atMost[c + 1] += counts.atMost[c];
    return counts;
}

SecondaryRays makeSecondaryRays(const SecondaryPass& pass, const std::vector<Ray>& primary,
                                const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                ThreadPool& pool) {
    return makeSecondaryRays(pass, primary, primaryHits, triangles, passRayCounts(pass, primaryHits, pool), pool);
}

SecondaryRays makeSecondaryRays(const SecondaryPass& pass, const std::vector<Ray>& primary,
                                const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                                const PassRayCounts& counts, ThreadPool& pool) {
    SecondaryRays out;
    out.slotCount = secondarySlots(pass, primary.size());
    // Chunks of primary rays made in parallel, each into its own stretch of one allocation,
    // then moved down in slot order. A stretch holds raysPerHit rays for each of the chunk's
    // hits (a miss sends none), not one per slot: where few primary rays hit (the Dragon's 48k
    // of 307k), the slots' size would be mostly untouched memory, zeroed and faulted in for
    // every pass (fresh pages cost a fault each on a VM).
    if (counts.primaryRays != primary.size() || primaryHits.size() != primary.size())
        throw InternalError("a secondary pass counted " + std::to_string(counts.primaryRays) + " primary hits of " +
                            std::to_string(primaryHits.size()) + " for " + std::to_string(primary.size()) + " primary rays");
    const std::size_t chunks = counts.chunks;
    auto chunkBegin = [&](std::size_t c) { return counts.chunkBegin(c); };
    const std::vector<std::size_t>& stretch = counts.atMost;
    reserveMapped(out.rays, stretch[chunks]);
    reserveMapped(out.slots, stretch[chunks]);
    out.rays.resize(stretch[chunks]);
    out.slots.resize(stretch[chunks]);
    std::vector<std::size_t> made(chunks, 0);
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        std::size_t next = stretch[c];
        secondaryRaysOfRange(pass, chunkBegin(c), chunkBegin(c + 1), primaryHits.data(),
                             [&](std::size_t i) -> const Ray& { return primary[i]; }, triangles,
                             [&](std::uint32_t slot, const Ray& ray) {
                                 out.rays[next] = ray;
                                 out.slots[next++] = slot;
                             });
        made[c] = next - stretch[c];
    });
    std::size_t total = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
        const std::size_t from = stretch[c];
        if (from != total) {
            std::copy(out.rays.begin() + std::ptrdiff_t(from), out.rays.begin() + std::ptrdiff_t(from + made[c]),
                      out.rays.begin() + std::ptrdiff_t(total));
            std::copy(out.slots.begin() + std::ptrdiff_t(from), out.slots.begin() + std::ptrdiff_t(from + made[c]),
                      out.slots.begin() + std::ptrdiff_t(total));
        }
        total += made[c];
    }
    out.rays.resize(total);
    out.slots.resize(total);
    return out;
}

void scatterToSlots(std::span<std::vector<Hit>> slotArrays, const std::uint32_t* slotOf, const std::uint16_t* passOf,
                    const Hit* hits, std::size_t count, ThreadPool* pool) {
    std::atomic<bool> pastTheEnd{false};
    forEachChunk(count, kFrameScanChunk, pool, [&](std::size_t, std::size_t begin, std::size_t end) {
        bool past = false;
        for (std::size_t i = begin; i < end; ++i) {
            std::vector<Hit>& slots = slotArrays[passOf ? passOf[i] : 0];
            if (slotOf[i] < slots.size())
                slots[slotOf[i]] = hits[i];
            else
                past = true;
        }
        if (past) pastTheEnd.store(true, std::memory_order_relaxed);
    });
    if (pastTheEnd.load()) throw InternalError("a secondary ray names a slot past its pass's slots");
}

std::vector<Hit> notTracedSlots(std::uint64_t slotCount, ThreadPool* pool) {
    return filledArray(std::size_t(slotCount), Hit{0.0f, kNotTracedPrim, 0.0f, 0.0f}, pool);
}

std::vector<Hit> hitsPerSlot(const SecondaryRays& rays, const std::vector<Hit>& traced, ThreadPool* pool) {
    if (traced.size() != rays.rays.size() || rays.slots.size() != rays.rays.size())
        throw InternalError("a secondary pass traced " + std::to_string(traced.size()) + " rays of " +
                            std::to_string(rays.rays.size()) + " (" + std::to_string(rays.slots.size()) + " slots named)");
    std::vector<Hit> slots = notTracedSlots(rays.slotCount, pool);
    scatterToSlots({&slots, 1}, rays.slots.data(), nullptr, traced.data(), traced.size(), pool);
    return slots;
}

FrameGeometry secondaryFrame(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                             const std::vector<Ray>& rays, const Box& sceneBox, ThreadPool* pool) {
    FrameGeometry g = frameGeometry(triangles, bounds, rays, sceneBox, 0, pool);
    g.query = HitQuery::Any;
    return g;
}

FrameGeometry passFrame(const FrameGeometry& primary, const std::vector<Ray>& rays, ThreadPool* pool) {
    FrameGeometry g = secondaryFrame(*primary.triangles, *primary.triangleBounds, rays, primary.sceneBox, pool);
    g.boundsColumns = primary.boundsColumns;
    g.trianglesVersion = primary.trianglesVersion;
    g.sceneId = primary.sceneId;
    return g;
}

}  // namespace dacrt
