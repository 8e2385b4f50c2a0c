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
           options.dacrt.rayGrouping == RayGrouping::Batches &&
           (pass.kind == shared::kPassOcclusion || pass.kind == shared::kPassShadow) &&
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

namespace {

// Group k's rays into b (its arrays cleared first, then grown to the group's most rays), with
// survey, where asked for, taking each ray as it is made.
void makeGroupRays(const FrameGeometry& primary, const std::vector<Hit>& primaryHits, const SecondaryPass& pass,
                   const MadeGroups& cut, std::size_t k, MadeGroupBuffers& b, RaySurvey* survey) {
    b.rays.clear();
    b.slots.clear();
    reserveMapped(b.rays, cut.raysAtMost(k));
    reserveMapped(b.slots, cut.raysAtMost(k));
    secondaryRaysOfRange(
        pass, cut.first[k], cut.first[k + 1], primaryHits.data(),
        [&](std::size_t i) -> const Ray& { return (*primary.rays)[i]; }, *primary.triangles,
        [&](std::uint32_t slot, const Ray& ray) {
            b.rays.push_back(ray);
            b.slots.push_back(slot);
            if (survey) survey->add(ray);
        });
}

// Group k's slots (its primary rays', slot = primary index * raysPerHit + sample) marked
// untraced, then its rays traced as a sequential DACRT (over the kept triangles where skips
// applies) and each answer written to its slot. Returns the trace's counters, its hits dropped.
TraceResult traceGroupToSlots(const FrameGeometry& primary, const SecondaryPass& pass, const MadeGroups& cut,
                              std::size_t k, const MadeGroupBuffers& b, const TriangleSkips* skips,
                              const DacrtOptions& dacrt, Hit* slots) {
    const Hit notTraced{0.0f, kNotTracedPrim, 0.0f, 0.0f};
    std::fill(slots + cut.first[k] * pass.raysPerHit, slots + cut.first[k + 1] * pass.raysPerHit, notTraced);
    if (b.rays.empty()) return {};
    const FrameGeometry g = passFrame(primary, b.rays);
    TraceResult part = traceSequential(skips ? withSkips(g, *skips) : g, dacrt);
    for (std::size_t i = 0; i < b.rays.size(); ++i) slots[b.slots[i]] = part.hits[i];
    part.hits = {};
    return part;
}

// The trace's plan: the cull's lines, then each worker's sequential DACRT of `largest` rays
// over g's triangles (a bound: the triangles' own arrays are shared), then the groups' line.
MemoryPlan groupsTracePlan(const FrameGeometry& g, const SkipSwitches& switches, const PassCull& cull,
                           std::size_t largest, std::size_t groups, unsigned workers, const DacrtOptions& dacrt,
                           const std::string& how) {
    MemoryPlan plan;
    planPassCull(g, switches, cull, plan);
    const std::string each = " (x" + std::to_string(workers) + " workers, at most)";
    const MemoryPlan one = sequentialPlan(g, largest, dacrt);
    for (const auto& [name, bytes] : one.buffers) plan.add(name + each, bytes * workers);
    plan.work.insert(plan.work.end(), one.work.begin(), one.work.end());
    plan.addWork("ray groups made and traced side by side", groups,
                 "each made by one of " + std::to_string(workers) + " workers " + how);
    return plan;
}

// An occlusion pass: each worker makes a group into its arrays and traces it at once.
MadePass traceOcclusionGroups(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                              const SecondaryPass& pass, const MadeGroups& cut, const TraceOptions& options,
                              ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, const PlanHook& onPlan) {
    MadePass out;
    const std::size_t groups = cut.count();
    const unsigned workers = unsigned(std::min<std::size_t>(pool.size(), groups));
    PassCull none;
    cullNothing(none);
    MemoryPlan plan = groupsTracePlan(unmadePassFrame(primary), options.skips, none, cut.largestAtMost(), groups, workers,
                                      options.dacrt, "and traced at once as a sequential DACRT: no array of the pass's rays");
    if (onPlan && !onPlan(plan)) return out;

    const auto start = Clock::now();
    out.result.hits = mappedArray<Hit>(secondarySlots(pass, cut.first.back()));  // every slot written by its group's worker
    std::vector<TraceResult> parts(groups);
    std::vector<double> makeMs(groups, 0.0);
    std::vector<std::uint64_t> made(groups, 0);
    if (buffers.size() < pool.size()) buffers.resize(pool.size());
    pool.parallelForRethrowing(groups, [&](std::size_t k, unsigned worker) {
        const auto makeStart = Clock::now();
        MadeGroupBuffers& b = buffers[worker];
        makeGroupRays(primary, primaryHits, pass, cut, k, b, nullptr);
        makeMs[k] = msSince(makeStart);
        made[k] = b.rays.size();
        parts[k] = traceGroupToSlots(primary, pass, cut, k, b, nullptr, options.dacrt, out.result.hits.data());
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

// The groups' rays one after another in slot order: the array makeSecondaryRays makes.
SecondaryRays groupsInOrder(const std::vector<MadeGroupBuffers>& buffers, std::size_t groups, std::uint64_t slotCount) {
    SecondaryRays rays;
    rays.slotCount = slotCount;
    std::size_t total = 0;
    for (std::size_t k = 0; k < groups; ++k) total += buffers[k].rays.size();
    reserveMapped(rays.rays, total);
    reserveMapped(rays.slots, total);
    for (std::size_t k = 0; k < groups; ++k) {
        rays.rays.insert(rays.rays.end(), buffers[k].rays.begin(), buffers[k].rays.end());
        rays.slots.insert(rays.slots.end(), buffers[k].slots.begin(), buffers[k].slots.end());
    }
    return rays;
}

// A shadow pass: every group made first (each surveying its rays for the cull's back-face
// tests), then the cull from the surveys, then the groups traced over the triangles it keeps.
MadePass traceShadowGroups(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                           const SecondaryPass& pass, const MadeGroups& cut, const TraceOptions& options,
                           ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, PassCull& cull,
                           const PlanHook& onPlan) {
    MadePass out;
    const std::size_t groups = cut.count();
    const unsigned workers = unsigned(std::min<std::size_t>(pool.size(), groups));
    if (buffers.size() < groups) buffers.resize(groups);
    std::vector<RaySurvey> surveys(groups);
    const auto start = Clock::now();
    pool.parallelForRethrowing(groups, [&](std::size_t k, unsigned) {
        makeGroupRays(primary, primaryHits, pass, cut, k, buffers[k], &surveys[k]);
    });
    const double makeWallMs = msSince(start);
    RaySurvey survey;
    std::size_t largest = 0;
    for (std::size_t k = 0; k < groups; ++k) {
        survey.merge(surveys[k]);
        largest = std::max(largest, buffers[k].rays.size());
    }
    out.rays = survey.rays;

    const auto cullStart = Clock::now();
    const FrameGeometry unmade = unmadePassFrame(primary);
    cullFromSurvey(unmade, survey, options.skips, pool, cull);
    const std::size_t traced = cull.skips.applied ? cull.skips.traced.size() : primary.triangles->size();
    // Where the rays made are few enough for the grid to pay, or fewer than the triangles kept
    // (subtrees), the pass goes on as its rays made first would: from their array.
    if (passCullMayDrop(survey.rays, primary.triangles->size(), false, options.skips) ||
        cpuTracesAsSubtrees(survey.rays, traced, HitQuery::Any, options, pool.size())) {
        out.unmade = groupsInOrder(buffers, groups, secondarySlots(pass, cut.first.back()));
        out.makeMs = makeWallMs;
        return out;
    }
    const FrameGeometry culled = cull.skips.applied ? withSkips(unmade, cull.skips) : unmade;
    MemoryPlan plan = groupsTracePlan(culled, options.skips, cull, largest, groups, workers, options.dacrt,
                                      "before the pass's cull, then traced as a sequential DACRT: no array of the pass's rays");
    const double cullMs = msSince(cullStart);
    if (onPlan && !onPlan(plan)) return out;

    const auto traceStart = Clock::now();
    out.result.hits = mappedArray<Hit>(secondarySlots(pass, cut.first.back()));
    std::vector<TraceResult> parts(groups);
    const TriangleSkips* skips = cull.skips.applied ? &cull.skips : nullptr;
    pool.parallelForRethrowing(groups, [&](std::size_t k, unsigned) {
        parts[k] = traceGroupToSlots(primary, pass, cut, k, buffers[k], skips, options.dacrt, out.result.hits.data());
    });
    const double traceMs = msSince(traceStart);
    for (const TraceResult& part : parts) out.result.counters.addTrace(part.counters);
    out.result.memory = std::move(plan);
    out.result.threads = workers;
    out.result.regions = 1;
    // Making, the cull and the trace one after another, each on every worker.
    out.result.phases.makeRays = makeWallMs;
    out.result.phases.skips = cullMs;
    out.result.phases.step1 = traceMs;
    return out;
}

}  // namespace

MadePass traceMadeSideBySide(const FrameGeometry& primary, const std::vector<Hit>& primaryHits,
                             const SecondaryPass& pass, const PassRayCounts& counts, const TraceOptions& options,
                             ThreadPool& pool, std::vector<MadeGroupBuffers>& buffers, PassCull& cull,
                             const PlanHook& onPlan) {
    const MadeGroups cut = madeGroups(counts, primaryHits, pass.raysPerHit, primary.triangles->size(), pool.size());
    const unsigned workers = unsigned(std::min<std::size_t>(pool.size(), cut.count()));
    const bool shadow = pass.kind == shared::kPassShadow;
    // What is made, from the counts, before any ray is: a shadow pass keeps every group's rays
    // until its cull has surveyed them all; an occlusion pass one group a worker.
    MemoryPlan making;
    making.add("hits per slot", secondarySlots(pass, counts.primaryRays) * sizeof(Hit));
    if (shadow)
        making.add("rays and slots of every group, made before the pass's cull (at most)",
                   std::uint64_t(counts.total()) * (sizeof(Ray) + sizeof(std::uint32_t)));
    else
        making.add("rays and slots of the group being made (x" + std::to_string(workers) + " workers, at most)",
                   std::uint64_t(cut.largestAtMost()) * (sizeof(Ray) + sizeof(std::uint32_t)) * workers);
    if (onPlan && !onPlan(making)) return {};
    return shadow ? traceShadowGroups(primary, primaryHits, pass, cut, options, pool, buffers, cull, onPlan)
                  : traceOcclusionGroups(primary, primaryHits, pass, cut, options, pool, buffers, onPlan);
}

}  // namespace dacrt
