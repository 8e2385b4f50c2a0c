#include "stress/stress.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <map>

#include "cpu/options.hpp"  // the command line's names of backends and options: the configurations'

namespace dacrt {
namespace {

bool sameBits(const RayHit& a, const RayHit& b) {
    return a.primitive == b.primitive && std::bit_cast<std::uint32_t>(a.t) == std::bit_cast<std::uint32_t>(b.t) &&
           std::bit_cast<std::uint32_t>(a.u) == std::bit_cast<std::uint32_t>(b.u) &&
           std::bit_cast<std::uint32_t>(a.v) == std::bit_cast<std::uint32_t>(b.v);
}

std::string describeHit(const RayHit& h) {
    if (!h.hit()) return "miss";
    char text[64];
    std::snprintf(text, sizeof text, "prim %u t %.9g", h.primitive, double(h.t));
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
    c.trace.backend = backend;
    return c;
}

// First differing index of two hit arrays, or -1.
long firstDifference(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
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
                c.trace.dacrt.split = s;
                out.push_back(c);
            }
            StressConfig sampled = config(base + " --split-cost ray-sampling", false, b);
            sampled.trace.dacrt.splitCost = SplitCost::RaySampling;
            out.push_back(sampled);
        }
        // The smallest leaves: 1 on the CPU; 4 on the GPU, where 1 took 495 s instead of 5 s
        // for the small watertight family on lavapipe (a workgroup-wide step per tiny node).
        for (std::uint32_t limit : {b == Backend::Gpu ? 4u : 1u, 256u}) {
            StressConfig c = config(base + " --ray-limit " + std::to_string(limit) + " --tri-limit " + std::to_string(limit), false, b);
            c.trace.dacrt.rayLimit = c.trace.dacrt.triLimit = limit;
            out.push_back(c);
        }
        if (b == Backend::CpuSeq) continue;  // one region, no division
        for (unsigned regions : {1u, 3u, 64u}) {
            StressConfig c = config(base + " --regions " + std::to_string(regions), false, b);
            c.trace.regions = regions;
            out.push_back(c);
        }
        for (DivisionAxis a : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z}) {
            StressConfig c = config(base + " --axis " + toString(a), false, b);
            c.trace.axis = a;
            out.push_back(c);
        }
        if (b == Backend::Gpu) {
            StressConfig c = config(base + " --workgroup-size 32", false, b);
            c.gpu.workgroupSize = 32;
            out.push_back(c);
        }
    }
    return out;
}

namespace {

// The case's triangles as arrays, vertex by vertex: triangle k is primitive k of the hits,
// also where the scene drops triangles with no area (the degenerate family has them).
TraceScene sceneOf(const StressCase& c) {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint8_t> singleSided;
    positions.reserve(9 * c.triangles.size());
    for (const Triangle& t : c.triangles) {
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            indices.push_back(std::uint32_t(positions.size() / 3));
            positions.insert(positions.end(), {v.x, v.y, v.z});
        }
        singleSided.push_back(t.cullBackFace != 0u ? 1 : 0);
    }
    return TraceScene::fromArrays(positions, indices, singleSided);
}

// The case's rays as arrays, their directions as made (canonical already: makeRay's or
// segmentRay's), so that the batch traces each bit for bit.
RayBatch raysOf(const StressCase& c) {
    std::vector<float> origins, directions, tmin, tmax;
    origins.reserve(3 * c.rays.size());
    directions.reserve(3 * c.rays.size());
    for (const Ray& r : c.rays) {
        origins.insert(origins.end(), {r.origin.x, r.origin.y, r.origin.z});
        directions.insert(directions.end(), {r.dir.x, r.dir.y, r.dir.z});
        tmin.push_back(r.tmin);
        tmax.push_back(r.tmax);
    }
    return RayBatch::fromArrays(origins, directions, tmin, tmax, DirectionLength::AsGiven);
}

}  // namespace

std::vector<RayHit> traceStressCase(const StressCase& c, const StressConfig& config, Tracer& tracer) {
    TracerOptions options = tracer.options();  // its device and validation stay
    options.trace = config.trace;
    options.gpu = config.gpu;
    options.embree = {};
    tracer.setOptions(options);
    const TraceScene scene = sceneOf(c);
    const RayBatch rays = raysOf(c);
    return (c.query == HitQuery::Any ? tracer.occluded(scene, rays) : tracer.trace(scene, rays)).hits;
}

StressTally tallyStressCase(const StressCase& c, const std::vector<RayHit>& hits, const std::vector<RayHit>* reference) {
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
            if (!hits[i].hit()) {
                ++t.leaks;
                example("ray " + std::to_string(i) + " leaks " + describeRay(c.rays[i], start));
            }
        }
        // An any-hit answer need not name its triangle (kUnnamedPrimitive); one that names a
        // ruled-out triangle is a self-intersection all the same.
        if (start && std::binary_search(start->ruledOut.begin(), start->ruledOut.end(), hits[i].primitive)) {
            ++t.selfIntersections;
            example("ray " + std::to_string(i) + " hits " + describeHit(hits[i]) + ", ruled out, " +
                    describeRay(c.rays[i], start));
        }
        if (reference && (anyHit ? hits[i].hit() != (*reference)[i].hit()
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
        const auto it = lowestOfGroup.find(hits[i].primitive);
        if (it != lowestOfGroup.end() && it->second != hits[i].primitive) {
            ++t.tieViolations;
            example("ray " + std::to_string(i) + " hit coincident copy " + std::to_string(hits[i].primitive) +
                    " instead of " + std::to_string(it->second));
        }
    }
    return t;
}

std::vector<DeterminismResult> determinismChecks(const std::vector<Backend>& backends, Tracer& tracer, StressSize size) {
    const StressCase scene = determinismCase(size);
    std::vector<DeterminismResult> out;
    StressConfig brute = defaultStressConfig(Backend::Brute);
    brute.trace.threads = 2;
    const std::vector<RayHit> reference = traceStressCase(scene, brute, tracer);

    auto check = [&](const std::string& name, const std::vector<std::pair<std::string, StressConfig>>& runs,
                     const std::vector<unsigned>& threadCounts) {
        DeterminismResult r{name, true, std::to_string(runs.size() * std::max<std::size_t>(threadCounts.size(), 1)) +
                                            " runs equal brute force bit for bit"};
        for (const auto& [label, cfg] : runs) {
            for (unsigned threads : threadCounts.empty() ? std::vector<unsigned>{0} : threadCounts) {
                StressConfig c = cfg;
                if (threads) c.trace.threads = threads;
                const std::vector<RayHit> hits = traceStressCase(scene, c, tracer);
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
        if (b == Backend::Gpu && tracer.device().empty()) continue;
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
                c.trace.regions = n;
                regions.emplace_back("--regions " + std::to_string(n), c);
            }
            check(base + ": regions 1 to 64", regions, {});
        }
    }
    return out;
}

}  // namespace dacrt
