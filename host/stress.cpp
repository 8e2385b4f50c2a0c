#include "stress.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "cpu_tracers.hpp"
#include "errors.hpp"
#include "gpu_tracer.hpp"
#include "timing.hpp"
#include "vk_context.hpp"

namespace dacrt {
namespace {

bool sameBits(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

std::string describeHit(const Hit& h) {
    if (h.prim == kMissPrim) return "miss";
    char text[64];
    std::snprintf(text, sizeof text, "prim %u t %.9g", h.prim, double(h.t));
    return text;
}

StressConfig config(const std::string& name, bool isDefault, Backend backend) {
    StressConfig c;
    c.name = name;
    c.isDefault = isDefault;
    c.trace.backend = backend;
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
            c.workgroupSize = 32;
            out.push_back(c);
        }
    }
    return out;
}

FrameGeometry stressGeometry(const StressCase& c, std::vector<Bounds>& bounds) {
    bounds = allTriangleBounds(c.triangles);
    return frameGeometry(c.triangles, bounds, c.rays, sceneBounds(c.triangles));
}

std::vector<Hit> traceStressCase(const StressCase& c, const StressConfig& config, StressDevices& devices) {
    std::vector<Bounds> bounds;
    const FrameGeometry g = stressGeometry(c, bounds);
    if (config.trace.backend != Backend::Gpu) return traceCpu(g, config.trace, devices.pool).hits;
    if (!devices.gpu) throw InputError("stress: the gpu backend needs a Vulkan device");
    return traceGpu(g, config.trace, GpuTuning{config.workgroupSize}, *devices.gpu, devices.pool, {}, devices.pipelines).hits;
}

StressTally tallyStressCase(const StressCase& c, const std::vector<Hit>& hits, const std::vector<Hit>* reference) {
    StressTally t;
    t.cases = 1;
    t.rays = c.rays.size();
    auto example = [&](const std::string& what) {
        if (t.examples.size() < 5) t.examples.push_back(c.family + " / " + c.name + ": " + what);
    };
    for (std::size_t i = 0; i < c.rays.size(); ++i) {
        if (c.mustHit[i]) {
            ++t.mustHit;
            if (hits[i].prim == kMissPrim) {
                ++t.leaks;
                const Ray& r = c.rays[i];
                char text[160];
                std::snprintf(text, sizeof text, "ray %zu leaks (origin %.9g %.9g %.9g, dir %.9g %.9g %.9g)", i,
                              double(r.origin.x), double(r.origin.y), double(r.origin.z), double(r.dir.x),
                              double(r.dir.y), double(r.dir.z));
                example(text);
            }
        }
        if (reference && !sameBits(hits[i], (*reference)[i])) {
            ++t.mismatches;
            example("ray " + std::to_string(i) + ": " + describeHit(hits[i]) + ", brute force " +
                    describeHit((*reference)[i]));
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

std::vector<DeterminismResult> determinismChecks(const std::vector<Backend>& backends, StressDevices& devices,
                                                 StressSize size) {
    const StressCase scene = determinismCase(size);
    std::vector<DeterminismResult> out;
    ThreadPool referencePool(2);
    StressDevices referenceDevices{referencePool, nullptr, nullptr};
    const std::vector<Hit> reference = traceStressCase(scene, defaultStressConfig(Backend::Brute), referenceDevices);

    auto check = [&](const std::string& name, const std::vector<std::pair<std::string, StressConfig>>& runs,
                     const std::vector<unsigned>& threadCounts) {
        DeterminismResult r{name, true, std::to_string(runs.size() * std::max<std::size_t>(threadCounts.size(), 1)) +
                                            " runs equal brute force bit for bit"};
        for (const auto& [label, cfg] : runs) {
            for (unsigned threads : threadCounts.empty() ? std::vector<unsigned>{0} : threadCounts) {
                std::unique_ptr<ThreadPool> own = threads ? std::make_unique<ThreadPool>(threads) : nullptr;
                StressDevices d{own ? *own : devices.pool, devices.gpu, devices.pipelines};
                StressConfig c = cfg;
                if (threads) c.trace.threads = threads;
                const std::vector<Hit> hits = traceStressCase(scene, c, d);
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
        if (b == Backend::Gpu && !devices.gpu) continue;
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

int runStressCommand(const StressCommand& command) {
    const std::vector<std::string> families = command.families.empty() ? stressFamilies() : command.families;
    const std::vector<Backend> backends = command.backends.empty()
                                              ? std::vector<Backend>{Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Gpu}
                                              : command.backends;
    const bool wantGpu = std::find(backends.begin(), backends.end(), Backend::Gpu) != backends.end();

    const auto generateStart = Clock::now();
    const std::vector<StressCase> cases = stressCases(families, command.size, command.seed);
    std::uint64_t totalRays = 0;
    for (const StressCase& c : cases) totalRays += c.rays.size();
    std::cerr << "dacrt stress: " << cases.size() << " cases, " << totalRays << " rays, generated in "
              << int(msSince(generateStart)) << " ms\n";

    ThreadPool pool(std::max(1u, std::thread::hardware_concurrency()));
    std::unique_ptr<vk::Context> gpu;
    std::unique_ptr<PipelineCache> pipelines;
    if (wantGpu) {
        gpu = std::make_unique<vk::Context>(vk::ContextOptions{command.device, command.validate});
        pipelines = std::make_unique<PipelineCache>(*gpu);
    }
    StressDevices devices{pool, gpu.get(), pipelines.get()};

    // Brute force is the reference every other configuration is compared with, bit for bit.
    std::vector<std::vector<Hit>> reference(cases.size());
    const StressConfig brute = defaultStressConfig(Backend::Brute);
    std::vector<double> referenceMs(cases.size());
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const auto start = Clock::now();
        reference[i] = traceStressCase(cases[i], brute, devices);
        referenceMs[i] = msSince(start);
    }

    struct Row {
        std::string config;
        bool isDefault;
        std::string family;
        StressTally tally;
    };
    std::vector<Row> rows;
    for (const StressConfig& cfg : stressConfigs(backends, command.withOptions)) {
        std::map<std::string, StressTally> byFamily;
        const auto start = Clock::now();
        for (std::size_t i = 0; i < cases.size(); ++i) {
            const auto caseStart = Clock::now();
            StressTally t;
            try {
                const std::vector<Hit> hits =
                    cfg.trace.backend == Backend::Brute ? reference[i] : traceStressCase(cases[i], cfg, devices);
                t = tallyStressCase(cases[i], hits, cfg.trace.backend == Backend::Brute ? nullptr : &reference[i]);
            } catch (const std::exception& e) {
                // A refusal is a result too: counted and shown, and the run goes on.
                t.cases = 1;
                t.rays = cases[i].rays.size();
                t.errors = 1;
                t.examples.push_back(cases[i].family + " / " + cases[i].name + ": error: " + e.what());
            }
            t.traceMs = t.slowestMs = cfg.trace.backend == Backend::Brute ? referenceMs[i] : msSince(caseStart);
            t.slowestCase = cases[i].name;
            byFamily[cases[i].family].add(t);
        }
        std::cerr << "dacrt stress: " << cfg.name << " done in " << int(msSince(start)) << " ms\n";
        for (const std::string& f : families) rows.push_back({cfg.name, cfg.isDefault, f, byFamily[f]});
    }

    std::vector<DeterminismResult> determinism;
    if (command.determinism) determinism = determinismChecks(backends, devices, command.size);

    bool ok = true;
    std::printf("%-38s %-12s %6s %9s %9s %6s %9s %5s %6s %9s  %s\n", "configuration", "family", "cases", "rays",
                "must-hit", "leaks", "!= brute", "ties", "errors", "ms", "slowest case (ms)");
    for (const Row& r : rows) {
        const bool bad = !r.tally.clean();
        if (bad && r.isDefault) ok = false;
        std::printf("%-38s %-12s %6llu %9llu %9llu %6llu %9llu %5llu %6llu %9.1f  %s (%.1f)%s\n",
                    (r.config + (r.isDefault ? " (default)" : "")).c_str(), r.family.c_str(),
                    (unsigned long long)r.tally.cases, (unsigned long long)r.tally.rays,
                    (unsigned long long)r.tally.mustHit, (unsigned long long)r.tally.leaks,
                    (unsigned long long)r.tally.mismatches, (unsigned long long)r.tally.tieViolations,
                    (unsigned long long)r.tally.errors, r.tally.traceMs, r.tally.slowestCase.c_str(), r.tally.slowestMs, bad ? "  <-- FAILS" : "");
    }
    for (const Row& r : rows)
        for (const std::string& e : r.tally.examples) std::printf("  %s: %s\n", r.config.c_str(), e.c_str());
    if (!determinism.empty()) std::printf("\ndeterminism (%s):\n", determinismCase(command.size).name.c_str());
    for (const DeterminismResult& d : determinism) {
        if (!d.holds) ok = false;
        std::printf("  %-34s %s  %s\n", d.name.c_str(), d.holds ? "holds" : "FAILS", d.detail.c_str());
    }
    if (gpu && command.validate) {
        std::printf("validation errors: %u\n", gpu->validationErrors());
        if (gpu->validationErrors() > 0) ok = false;
    }

    if (!command.jsonPath.empty()) {
        nlohmann::ordered_json j;
        j["seed"] = command.seed;
        j["size"] = command.size == StressSize::Large ? "large" : "small";
        if (gpu) j["device"] = gpu->info().name + " (" + gpu->info().driver + ")";
        for (const Row& r : rows)
            j["rows"].push_back({{"configuration", r.config}, {"default", r.isDefault}, {"family", r.family},
                                 {"cases", r.tally.cases}, {"rays", r.tally.rays}, {"must_hit", r.tally.mustHit},
                                 {"leaks", r.tally.leaks}, {"differ_from_brute", r.tally.mismatches},
                                 {"tie_violations", r.tally.tieViolations}, {"errors", r.tally.errors}, {"ms", r.tally.traceMs},
                                 {"slowest_case", r.tally.slowestCase}, {"slowest_case_ms", r.tally.slowestMs},
                                 {"examples", r.tally.examples}});
        for (const DeterminismResult& d : determinism)
            j["determinism"].push_back({{"check", d.name}, {"holds", d.holds}, {"detail", d.detail}});
        std::ofstream f(command.jsonPath);
        if (!f) throw InputError(command.jsonPath + ": cannot write the JSON file");
        f << j.dump(2) << "\n";
    }
    std::printf("%s\n", ok ? "stress: every default configuration is clean and every determinism check holds"
                           : "stress: FAILED (see the rows marked above)");
    return ok ? 0 : 1;
}

}  // namespace dacrt
