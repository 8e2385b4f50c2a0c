#include "library/frame_passes.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/lights.hpp"
#include "core/timing.hpp"
#include "library/api_results.hpp"

namespace dacrt {

std::vector<SecondaryPass> secondaryPasses(const std::vector<Light>& lights, const PassOptions& o, const Box& box,
                                           std::uint32_t seed) {
    std::vector<SecondaryPass> passes;
    for (const Light& light : lights) {
        SecondaryPass p;
        p.name = "shadow: " + (light.name.empty() ? toString(light.type) + " light" : light.name);
        p.kind = shared::kPassShadow;
        p.light = shadowLightOf(light);
        passes.push_back(p);
    }
    if (o.occlusionSamples > 0) {
        SecondaryPass p;
        p.name = "occlusion";
        p.kind = shared::kPassOcclusion;
        p.raysPerHit = o.occlusionSamples;
        p.occlusionDistance = occlusionDistance(o, box);
        p.sampleSeed = seed;
        passes.push_back(p);
    }
    return passes;
}

namespace {

// Samples of an occlusion pass per batch: all of them, but where the device cannot hold the
// pass's slots at once (secondaryPassCapacity: one binding of rays on a device without buffer
// device addresses, or its memory), as many as it can; `limit` names what holds no more.
std::uint32_t samplesPerBatch(const SecondaryPass& pass, std::uint64_t primaryRays, const BackendDispatcher& backends,
                              const BackendRequest& request, std::string& limit) {
    if (primaryRays == 0) return pass.raysPerHit;
    const PassCapacity capacity = backends.secondaryPassCapacity(request);
    limit = capacity.limit;
    return std::uint32_t(std::clamp<std::uint64_t>(capacity.slots / primaryRays, 1, pass.raysPerHit));
}

// A batch's result folded into the whole pass's: slots, rays, time and counters.
void addBatch(TracedPass& whole, const SecondaryPass& batch, TracedPass&& part, std::uint64_t primaryRays) {
    const std::uint32_t total = whole.pass.raysPerHit;
    if (whole.result.hits.empty()) {
        whole.result.hits = notTracedSlots(primaryRays * total);
        whole.result.memory = part.result.memory;
        whole.result.gpu = part.result.gpu;
        whole.result.regions = part.result.regions;
        whole.result.axis = part.result.axis;
        whole.result.threads = part.result.threads;
    } else if (whole.result.gpu && part.result.gpu) {
        whole.result.gpu->dispatchMs.insert(whole.result.gpu->dispatchMs.end(), part.result.gpu->dispatchMs.begin(),
                                            part.result.gpu->dispatchMs.end());
        whole.result.gpu->dispatches += part.result.gpu->dispatches;
    }
    for (std::uint64_t i = 0; i < primaryRays; ++i)
        for (std::uint32_t k = 0; k < batch.raysPerHit; ++k)
            whole.result.hits[i * total + batch.firstSample + k] = part.result.hits[i * batch.raysPerHit + k];
    whole.result.counters.add(part.result.counters);
    whole.result.phases.add(part.result.phases);
    whole.rays += part.rays;
    whole.ms += part.ms;
}

}  // namespace

bool passesTracedTogether(const std::vector<SecondaryPass>& passes, const std::vector<Hit>& primaryHits,
                          std::size_t triangles, const BackendRequest& request) {
    const Backend b = request.trace.backend;
    const PassTracing tracing = request.trace.dacrt.passTracing;
    if (passes.size() < 2 || passes.size() > BackendDispatcher::kMostPassesTogether ||
        (b != Backend::Cpu && b != Backend::CpuSeq) || tracing == PassTracing::Apart)
        return false;
    if (tracing == PassTracing::Together) return true;  // checkOptionCombinations: not with octant groupings
    if (request.trace.dacrt.rayGrouping != RayGrouping::Batches && request.trace.dacrt.rayGrouping != RayGrouping::Slots)
        return false;
    if (BackendDispatcher::slotsTogether(passes, primaryHits.size()) > kMaxSecondarySlots)
        return false;  // more than one trace's 32-bit ids
    std::uint64_t raysPerSurface = 0;
    for (const SecondaryPass& pass : passes) raysPerSurface += pass.raysPerHit;
    return surfacesSendingRays(primaryHits) * raysPerSurface < triangles;
}

std::vector<TracedPass> traceSecondaryPasses(const std::vector<SecondaryPass>& passes, const FrameGeometry& primary,
                                             const std::vector<Hit>& primaryHits, BackendDispatcher& backends,
                                             const BackendRequest& request, const PlanHook& onPlan) {
    std::vector<TracedPass> traced;
    const std::uint64_t primaryRays = primary.rays->size();
    if (passesTracedTogether(passes, primaryHits, primary.triangles->size(), request)) {
        const auto start = Clock::now();
        std::vector<BackendDispatcher::PassTrace> t =
            backends.traceSecondaryTogether(primary, primaryHits, passes, request, onPlan);
        if (t.empty()) return traced;  // stopped at the plan
        const double ms = msSince(start);
        for (std::size_t p = 0; p < passes.size(); ++p)
            traced.push_back(TracedPass{passes[p], std::move(t[p].result), t[p].rays, p + 1 == passes.size() ? ms : 0.0,
                                        passes.size() - 1});
        return traced;
    }
    for (const SecondaryPass& pass : passes) {
        std::string limit;
        const std::uint32_t batch = samplesPerBatch(pass, primaryRays, backends, request, limit);
        TracedPass whole{pass, {}, 0, 0.0};
        for (std::uint32_t first = 0; first < pass.raysPerHit; first += batch) {
            SecondaryPass part = pass;
            part.firstSample = first;
            part.raysPerHit = std::min(batch, pass.raysPerHit - first);
            part.samplesPerHit = pass.raysPerHit;
            const auto start = Clock::now();
            BackendDispatcher::PassTrace t = backends.traceSecondary(primary, primaryHits, part, request, onPlan);
            if (t.result.hits.empty()) return traced;  // stopped at the plan
            if (batch == pass.raysPerHit) {
                whole = TracedPass{pass, std::move(t.result), t.rays, msSince(start)};
                break;
            }
            addBatch(whole, part, TracedPass{part, std::move(t.result), t.rays, msSince(start)}, primaryRays);
        }
        if (batch < pass.raysPerHit)
            whole.result.memory.addWork("occlusion batches", (pass.raysPerHit + batch - 1) / batch,
                                        std::to_string(batch) + " samples per hit each: the slots that fit " + limit);
        traced.push_back(std::move(whole));
    }
    return traced;
}

FramePass framePassOf(const SecondaryPass& pass) {
    const ShadowLight& l = pass.light;
    const LightKind kind = l.type == shared::kLightPoint
                               ? LightKind::Point
                               : (l.type == shared::kLightSpot ? LightKind::Spot : LightKind::Directional);
    return FramePass{.name = pass.name,
                     .kind = pass.kind == shared::kPassShadow ? PassKind::Shadow : PassKind::Occlusion,
                     .light = {kind, {l.position.x, l.position.y, l.position.z},
                               {l.direction.x, l.direction.y, l.direction.z}, l.range, l.cosOuterSquared},
                     .raysPerHit = pass.raysPerHit,
                     .occlusionDistance = pass.occlusionDistance,
                     .sampleSeed = pass.sampleSeed};
}

SecondaryPass secondaryPassOf(const FramePass& pass) {
    SecondaryPass s;
    s.name = pass.name;
    s.kind = pass.kind == PassKind::Shadow ? shared::kPassShadow : shared::kPassOcclusion;
    const PassLight& l = pass.light;
    s.light.type = l.kind == LightKind::Point ? shared::kLightPoint
                                              : (l.kind == LightKind::Spot ? shared::kLightSpot : shared::kLightDirectional);
    s.light.position = {l.position[0], l.position[1], l.position[2]};
    s.light.direction = {l.direction[0], l.direction[1], l.direction[2]};
    s.light.range = l.range;
    s.light.cosOuterSquared = l.cosOuterSquared;
    s.raysPerHit = pass.raysPerHit;
    s.occlusionDistance = pass.occlusionDistance;
    s.sampleSeed = pass.sampleSeed;
    return s;
}

MemoryPlan secondaryPassBound(const SecondaryPass& pass, std::uint64_t primaryRays, Backend backend) {
    const std::uint64_t slots = secondarySlots(pass, primaryRays);
    MemoryPlan plan;
    plan.add("rays (at most)", slots * sizeof(Ray));
    plan.add("hits (at most)", slots * sizeof(Hit));
    plan.add("hits per slot", slots * sizeof(Hit));
    if (backend == Backend::Gpu) {
        plan.add("device: ray ids and scratch", slots * 8);
    } else if (backend == Backend::Cpu || backend == Backend::CpuSeq) {
        plan.add("ray ids and binning (at most)", slots * 8);
        plan.add("partition scratch (at most, per thread)", slots * 4);
        // Passes traced together (PassTracing) copy their rays into one merged array, with
        // each ray's slot and pass, before the passes' own copies are freed.
        plan.add("its rays merged with the frame's other passes' (--pass-tracing, at most)",
                 slots * (sizeof(Ray) + sizeof(std::uint32_t) + sizeof(std::uint16_t)));
    }
    plan.addWork("rays (at most)", slots,
                 std::to_string(primaryRays) + " primary rays x " + std::to_string(pass.raysPerHit) +
                     "; none where the primary ray misses or the surface cannot send one");
    return plan;
}

FramePlan passPlanBound(const FramePass& pass, std::uint64_t primaryRays, Backend backend) {
    return framePlanOf(secondaryPassBound(secondaryPassOf(pass), primaryRays, backend));
}

FramePlan frameMemoryBound(std::uint64_t primaryRays, const std::vector<FramePass>& passes) {
    MemoryPlan plan;
    plan.add("rays", primaryRays * sizeof(Ray));
    plan.add("hits", primaryRays * sizeof(Hit));
    plan.addWork("rays", primaryRays, "one per pixel");
    for (const FramePass& pass : passes) {
        const std::uint64_t slots = secondarySlots(secondaryPassOf(pass), primaryRays);
        plan.add("hits per slot: " + pass.name, slots * sizeof(Hit));
        plan.addWork("slots: " + pass.name, slots,
                     std::to_string(primaryRays) + " primary rays x " + std::to_string(pass.raysPerHit));
    }
    return framePlanOf(plan);
}

}  // namespace dacrt
