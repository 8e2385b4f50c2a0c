#include "stress/stress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "cpu/cpu_tracers.hpp"
#include "core/errors.hpp"
#include "gpu/gpu_tracer.hpp"
#include "core/timing.hpp"
#include "gpu/context.hpp"

namespace dacrt {
namespace {

bool sameBits(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

std::string describeHit(const Hit& h) {
    if (h.prim == kMissPrim) return "miss";
    char text[64];
    std::snprintf(text, sizeof text, "prim %u t %.9g", h.prim, double(h.t));
    return text;
}

// The ray, and for one that starts on a surface, where and at what angle to the surface
// (the elevation above the start triangle's plane) it leaves.
std::string describeRay(const Ray& r, const SurfaceStart* start) {
    char text[200];
    std::snprintf(text, sizeof text, "(origin %.9g %.9g %.9g, dir %.9g %.9g %.9g, tmax %.9g)", double(r.origin.x),
                  double(r.origin.y), double(r.origin.z), double(r.dir.x), double(r.dir.y), double(r.dir.z),
                  double(r.tmax));
    if (!start) return text;
    const double sine = glm::dot(glm::normalize(glm::dvec3(r.dir)), start->normal);
    char angle[48];
    std::snprintf(angle, sizeof angle, ", elevation %.3g rad", std::asin(std::clamp(sine, -1.0, 1.0)));
    return std::string(text) + " from " + start->where + angle;
}

StressConfig config(const std::string& name, bool isDefault, Backend backend) {
    StressConfig c;
    c.name = name;
    c.isDefault = isDefault;
    c.request.trace.backend = backend;
    return c;
}

// First differing index of two hit arrays, or -1.
long firstDifference(const std::vector<Hit>& a, const std::vector<Hit>& b) {
    if (a.size() != b.size()) return 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (!sameBits(a[i], b[i])) return long(i);
    return -1;
}

}  // namespace

StressConfig defaultStressConfig(Backend backend) { return config(toString(backend), true, backend); }

void StressTally::add(const StressTally& o) {
    cases += o.cases;
    rays += o.rays;
    mustHit += o.mustHit;
    leaks += o.leaks;
    selfIntersections += o.selfIntersections;
    mismatches += o.mismatches;
    tieViolations += o.tieViolations;
    errors += o.errors;
    traceMs += o.traceMs;
    if (o.slowestMs > slowestMs) {
        slowestMs = o.slowestMs;
        slowestCase = o.slowestCase;
    }
    for (const std::string& e : o.examples)
        if (examples.size() < 5) examples.push_back(e);
}

std::vector<StressConfig> stressConfigs(const std::vector<Backend>& backends, bool withOptions) {
    std::vector<StressConfig> out;
    for (Backend b : backends) out.push_back(defaultStressConfig(b));
    if (!withOptions) return out;
    for (Backend b : backends) {
        const std::string base = toString(b);
        if (b == Backend::Brute) continue;  // brute force has no options that change its tests
        if (b == Backend::CpuSeq || b == Backend::Cpu) {
            for (SplitMethod s : {SplitMethod::CentroidMean, SplitMethod::SampledMean}) {
                StressConfig c = config(base + " --split " + toString(s), false, b);
                c.request.trace.dacrt.split = s;
                out.push_back(c);
            }
        }
        // The smallest leaves: 1 on the CPU; 4 on the GPU, where 1 took 495 s instead of 5 s
        // for the small watertight family on lavapipe (a workgroup-wide step per tiny node).
        for (std::uint32_t limit : {b == Backend::Gpu ? 4u : 1u, 256u}) {
            StressConfig c = config(base + " --ray-limit " + std::to_string(limit) + " --tri-limit " + std::to_string(limit), false, b);
            c.request.trace.dacrt.rayLimit = c.request.trace.dacrt.triLimit = limit;
            out.push_back(c);
        }
        if (b == Backend::CpuSeq) continue;  // one region, no division
        for (unsigned regions : {1u, 3u, 64u}) {
            StressConfig c = config(base + " --regions " + std::to_string(regions), false, b);
            c.request.trace.regions = regions;
            out.push_back(c);
        }
        for (DivisionAxis a : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z}) {
            StressConfig c = config(base + " --axis " + toString(a), false, b);
            c.request.trace.axis = a;
            out.push_back(c);
        }
        if (b == Backend::Gpu) {
            StressConfig c = config(base + " --workgroup-size 32", false, b);
            c.request.gpuTuning.workgroupSize = 32;
            out.push_back(c);
        }
    }
    return out;
}

FrameGeometry stressGeometry(const StressCase& c, std::vector<Bounds>& bounds) {
    bounds = allTriangleBounds(c.triangles);
    FrameGeometry g = frameGeometry(c.triangles, bounds, c.rays, sceneBounds(c.triangles));
    g.query = c.query;
    return g;
}

std::vector<Hit> traceStressCase(const StressCase& c, const StressConfig& config, BackendDispatcher& backends) {
    std::vector<Bounds> bounds;
    const FrameGeometry g = stressGeometry(c, bounds);
    if (config.request.trace.backend == Backend::Gpu && !backends.gpuContext())
        throw InputError("stress: the gpu backend needs a Vulkan device");
    return backends.trace(g, config.request).hits;
}

StressTally tallyStressCase(const StressCase& c, const std::vector<Hit>& hits, const std::vector<Hit>* reference) {
    StressTally t;
    t.cases = 1;
    t.rays = c.rays.size();
    auto example = [&](const std::string& what) {
        if (t.examples.size() < 5) t.examples.push_back(c.family + " / " + c.name + ": " + what);
    };
    const bool anyHit = c.query == HitQuery::Any;
    for (std::size_t i = 0; i < c.rays.size(); ++i) {
        const SurfaceStart* start =
            i < c.startOf.size() && c.startOf[i] != kNoSurfaceStart ? &c.starts[c.startOf[i]] : nullptr;
        if (c.mustHit[i]) {
            ++t.mustHit;
            if (hits[i].prim == kMissPrim) {
                ++t.leaks;
                example("ray " + std::to_string(i) + " leaks " + describeRay(c.rays[i], start));
            }
        }
        // An any-hit answer need not name its triangle (kUnnamedHitPrim); one that names a
        // ruled-out triangle is a self-intersection all the same.
        if (start && std::binary_search(start->ruledOut.begin(), start->ruledOut.end(), hits[i].prim)) {
            ++t.selfIntersections;
            example("ray " + std::to_string(i) + " hits " + describeHit(hits[i]) + ", ruled out, " +
                    describeRay(c.rays[i], start));
        }
        if (reference && (anyHit ? (hits[i].prim == kMissPrim) != ((*reference)[i].prim == kMissPrim)
                                 : !sameBits(hits[i], (*reference)[i]))) {
            ++t.mismatches;
            example("ray " + std::to_string(i) + ": " + describeHit(hits[i]) + ", brute force " +
                    describeHit((*reference)[i]) + (anyHit ? " (any hit)" : ""));
        }
    }
    std::map<std::uint32_t, std::uint32_t> lowestOfGroup;
    for (const std::vector<std::uint32_t>& group : c.coincidentGroups)
        for (std::uint32_t id : group) lowestOfGroup[id] = *std::min_element(group.begin(), group.end());
    for (std::size_t i = 0; i < hits.size() && !lowestOfGroup.empty(); ++i) {
        const auto it = lowestOfGroup.find(hits[i].prim);
        if (it != lowestOfGroup.end() && it->second != hits[i].prim) {
            ++t.tieViolations;
            example("ray " + std::to_string(i) + " hit coincident copy " + std::to_string(hits[i].prim) +
                    " instead of " + std::to_string(it->second));
        }
    }
    return t;
}

std::vector<DeterminismResult> determinismChecks(const std::vector<Backend>& backends, BackendDispatcher& dispatcher,
                                                 StressSize size) {
    const StressCase scene = determinismCase(size);
    std::vector<DeterminismResult> out;
    StressConfig brute = defaultStressConfig(Backend::Brute);
    brute.request.trace.threads = 2;
    const std::vector<Hit> reference = traceStressCase(scene, brute, dispatcher);

    auto check = [&](const std::string& name, const std::vector<std::pair<std::string, StressConfig>>& runs,
                     const std::vector<unsigned>& threadCounts) {
        DeterminismResult r{name, true, std::to_string(runs.size() * std::max<std::size_t>(threadCounts.size(), 1)) +
                                            " runs equal brute force bit for bit"};
        for (const auto& [label, cfg] : runs) {
            for (unsigned threads : threadCounts.empty() ? std::vector<unsigned>{0} : threadCounts) {
                StressConfig c = cfg;
                if (threads) c.request.trace.threads = threads;
                const std::vector<Hit> hits = traceStressCase(scene, c, dispatcher);
                const long at = firstDifference(hits, reference);
                if (at >= 0 && r.holds) {
                    r.holds = false;
                    r.detail = label + (threads ? " with " + std::to_string(threads) + " threads" : std::string()) +
                               ": ray " + std::to_string(at) + " gave " + describeHit(hits[std::size_t(at)]) +
                               ", brute force " + describeHit(reference[std::size_t(at)]);
                }
            }
        }
        out.push_back(r);
    };

    for (Backend b : backends) {
        const std::string base = toString(b);
        if (b == Backend::Gpu && !dispatcher.gpuContext()) continue;
        std::vector<std::pair<std::string, StressConfig>> repeats;
        for (int k = 0; k < 10; ++k) repeats.emplace_back("run " + std::to_string(k), defaultStressConfig(b));
        check(base + ": 10 runs", repeats, {});
        if (b != Backend::CpuSeq && b != Backend::Gpu) {
            // Thread counts change the default region count of cpu, and the work split of both.
            check(base + ": threads 1, 2, 3, 4, 8", {{base, defaultStressConfig(b)}}, {1, 2, 3, 4, 8});
        }
        if (b == Backend::Cpu || b == Backend::Gpu) {
            std::vector<std::pair<std::string, StressConfig>> regions;
            for (unsigned n = 1; n <= 64; ++n) {
                StressConfig c = defaultStressConfig(b);
                c.request.trace.regions = n;
                regions.emplace_back("--regions " + std::to_string(n), c);
            }
            check(base + ": regions 1 to 64", regions, {});
        }
    }
    return out;
}

}  // namespace dacrt
