#include "cmd/frame_passes.hpp"

#include <cmath>

#include "core/errors.hpp"
#include "core/lights.hpp"
#include "core/timing.hpp"

namespace dacrt {

void checkPassOptions(const PassOptions& o) {
    for (const std::string& light : o.lights) parseLightSpec(light);
    if (o.occlusionSamples > 1024) throw InputError("--ao " + std::to_string(o.occlusionSamples) + ": at most 1024 rays per hit");
    if (!std::isfinite(o.occlusionDistance) || o.occlusionDistance < 0.0 || o.occlusionDistance > kMaxCoordinate)
        throw InputError("--ao-distance must be a positive length (0: a tenth of the scene's diagonal), at most " +
                         std::to_string(kMaxCoordinate));
}

float occlusionDistance(const PassOptions& o, const Box& box) {
    if (o.occlusionDistance > 0.0) return float(o.occlusionDistance);
    return float(0.1 * glm::length(glm::dvec3(box.extent())));
}

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

std::vector<TracedPass> traceSecondaryPasses(const std::vector<SecondaryPass>& passes, const FrameGeometry& primary,
                                             const std::vector<Hit>& primaryHits, BackendDispatcher& backends,
                                             const BackendRequest& request, const PlanHook& onPlan) {
    std::vector<TracedPass> traced;
    for (const SecondaryPass& pass : passes) {
        const auto start = Clock::now();
        BackendDispatcher::PassTrace t = backends.traceSecondary(primary, primaryHits, pass, request, onPlan);
        traced.push_back(TracedPass{pass, std::move(t.result), t.rays, msSince(start)});
    }
    return traced;
}

Lighting lightingOf(const std::vector<Light>& lights, const std::vector<TracedPass>& traced) {
    Lighting l;
    std::size_t shadow = 0;
    for (const TracedPass& t : traced) {
        if (t.pass.kind == shared::kPassOcclusion) {
            l.occlusion = &t.result.hits;
            l.occlusionSamples = t.pass.raysPerHit;
        } else {
            l.lights.push_back(&lights.at(shadow++));
            l.shadows.push_back(&t.result.hits);
        }
    }
    return l;
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
    }
    plan.addWork("rays (at most)", slots,
                 std::to_string(primaryRays) + " primary rays x " + std::to_string(pass.raysPerHit) +
                     "; none where the primary ray misses or the surface cannot send one");
    return plan;
}

}  // namespace dacrt
