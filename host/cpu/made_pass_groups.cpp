#include "cpu/made_pass_groups.hpp"

#include <algorithm>
#include <string>

#include "core/mapped_memory.hpp"
#include "core/timing.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/pass_cull.hpp"
#include "cpu/ray_grouping.hpp"

namespace dacrt {
namespace {

// A pass's frame before its rays are made: the primary frame's triangles, for the plan of a
// group's sequential DACRT from the counts (sequentialPlan reads no ray of a frame that is not
// an image's).
FrameGeometry unmadePassFrame(const FrameGeometry& primary) {
    FrameGeometry g = primary;
    g.rays = nullptr;
    g.imageWidth = 0;
    g.raysShareStart = g.uniformByConstruction = false;
    g.frustum.reset();
    g.tracedTriangles = nullptr;  // a pass traces every triangle its own cull keeps (none dropped here)
    g.query = HitQuery::Any;
    return g;
}

}  // namespace

bool tracesMadeSideBySide(const SecondaryPass& pass, std::uint64_t raysAtMost, std::size_t triangles,
                          const TraceOptions& options, unsigned workers) {
    return options.backend == Backend::Cpu && options.regions == 0 && workers > 1 &&
           options.dacrt.rayGrouping == RayGrouping::Batches && pass.kind == shared::kPassOcclusion &&
           raysAtMost > 1 && !passCullMayDrop(raysAtMost, triangles, false, options.skips) &&
           !cpuTracesAsSubtrees(raysAtMost, triangles, HitQuery::Any, options, workers);
}

MadeGroups madeGroups(const PassRayCounts& counts, const std::vector<Hit>& primaryHits, std::uint32_t raysPerHit,
                      std::size_t triangles, unsigned workers) {
    const std::vector<std::size_t> batchStarts = rayBatches(counts.total(), passBatchRays(triangles), workers);
    MadeGroups groups{{0}, {0}};
    for (std::size_t b = 1; b + 1 < batchStarts.size(); ++b) {
        // The chunk in which the rays so far reach the batch's start, then its ray that does.
        const std::size_t c = std::size_t(std::lower_bound(counts.atMost.begin(), counts.atMost.end(), batchStarts[b]) -
                                          counts.atMost.begin());
        if (c == 0 || c > counts.chunks) continue;
        std::size_t i = counts.chunkBegin(c - 1), rays = counts.atMost[c - 1];
        while (rays < batchStarts[b]) rays += hitSendsRays(primaryHits[i++]) ? raysPerHit : 0;
        if (i > groups.first.back() && i < counts.primaryRays) {
            groups.first.push_back(i);
            groups.raysBefore.push_back(rays);
        }
    }
    groups.first.push_back(counts.primaryRays);
    groups.raysBefore.push_back(counts.total());
    return groups;
}

MadePass traceMadeSideBySide(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                             const SecondaryPass& pass, const PassRayCounts& counts, const TraceOptions& options,
                             ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, const PlanHook& onPlan) {
    MadePass out;
    const DacrtOptions& dacrt = options.dacrt;
    const MadeGroups cut = madeGroups(counts, primaryHits, pass.raysPerHit, primary.triangles->size(), pool.size());
    const std::size_t groups = cut.count();
    const unsigned workers = unsigned(std::min<std::size_t>(pool.size(), groups));
    std::size_t largest = 0;
    for (std::size_t k = 0; k < groups; ++k) largest = std::max(largest, cut.raysAtMost(k));

    // The plans, from the counts, before any ray is made.
    const std::uint64_t slotCount = secondarySlots(pass, counts.primaryRays);
    const std::string each = " (x" + std::to_string(workers) + " workers, at most)";
    MemoryPlan making;
    making.add("hits per slot", slotCount * sizeof(Hit));
    making.add("rays and slots of the group being made" + each,
               std::uint64_t(largest) * (sizeof(Ray) + sizeof(std::uint32_t)) * workers);
    if (onPlan && !onPlan(making)) return out;
    MemoryPlan plan;
    PassCull none;
    cullNothing(none);
    planPassCull(primary, options.skips, none, plan);
    const MemoryPlan one = sequentialPlan(unmadePassFrame(primary), largest, dacrt);
    for (const auto& [name, bytes] : one.buffers) plan.add(name + each, bytes * workers);
    plan.work.insert(plan.work.end(), one.work.begin(), one.work.end());
    plan.addWork("ray groups made and traced side by side", groups,
                 "each made by one of " + std::to_string(workers) +
                     " workers and traced at once as a sequential DACRT: no array of the pass's rays");
    if (onPlan && !onPlan(plan)) return out;

    const auto start = Clock::now();
    out.result.hits = mappedArray<Hit>(slotCount);  // every slot written by its group's worker
    std::vector<TraceResult> parts(groups);
    std::vector<double> makeMs(groups, 0.0);
    std::vector<std::uint64_t> made(groups, 0);
    if (buffers.size() < pool.size()) buffers.resize(pool.size());
    const Hit notTraced{0.0f, kNotTracedPrim, 0.0f, 0.0f};
    pool.parallelForRethrowing(groups, [&](std::size_t k, unsigned worker) {
        const auto makeStart = Clock::now();
        MadeGroupBuffers& b = buffers[worker];
        const std::size_t first = cut.first[k], end = cut.first[k + 1];
        b.rays.clear();
        b.slots.clear();
        reserveMapped(b.rays, cut.raysAtMost(k));
        reserveMapped(b.slots, cut.raysAtMost(k));
        secondaryRaysOfRange(
            pass, first, end, primaryHits.data(), [&](std::size_t i) -> const Ray& { return (*primary.rays)[i]; },
            *primary.triangles, [&](std::uint32_t slot, const Ray& ray) {
                b.rays.push_back(ray);
                b.slots.push_back(slot);
            });
        makeMs[k] = msSince(makeStart);
        made[k] = b.rays.size();
        // The group's slots are its primary rays' (slot = primary index * raysPerHit + sample).
        Hit* const slots = out.result.hits.data();
        std::fill(slots + first * pass.raysPerHit, slots + end * pass.raysPerHit, notTraced);
        if (b.rays.empty()) return;
        TraceResult part = traceSequential(passFrame(primary, b.rays), dacrt);
        for (std::size_t i = 0; i < b.rays.size(); ++i) slots[b.slots[i]] = part.hits[i];
        part.hits = {};
        parts[k] = std::move(part);
    });
    const double wallMs = msSince(start);
    double makeSum = 0.0;
    for (std::size_t k = 0; k < groups; ++k) {
        out.result.counters.addTrace(parts[k].counters);
        out.rays += made[k];
        makeSum += makeMs[k];
    }
    out.result.memory = std::move(plan);
    out.result.threads = workers;
    out.result.regions = 1;
    // The workers' making and tracing overlap: each part is their mean time at it.
    out.result.phases.makeRays = makeSum / double(workers);
    out.result.phases.step1 = std::max(0.0, wallMs - *out.result.phases.makeRays);
    return out;
}

}  // namespace dacrt
