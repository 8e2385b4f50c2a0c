// The `dacrt stress` command: cases, the brute-force reference, every configuration, the
// determinism checks, then the table, the JSON and the verdict.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "app/exit_codes.hpp"
#include "app/output_paths.hpp"
#include "app/progress.hpp"
#include "core/atomic_file.hpp"
#include "core/timing.hpp"
#include "stress/stress.hpp"

namespace dacrt {
namespace {

struct StressRow {
    std::string config;
    bool isDefault = false;
    std::string family;
    StressTally tally;
};

struct BruteReference {
    std::vector<std::vector<RayHit>> hits;  // per case
    std::vector<double> ms;
};

std::vector<StressCase> generateCases(const StressCommand& command, const std::vector<std::string>& families) {
    const auto start = Clock::now();
    std::vector<StressCase> cases = stressCases(families, command.size, command.seed);
    std::uint64_t rays = 0;
    for (const StressCase& c : cases) rays += c.rays.size();
    std::cerr << "dacrt stress: " << cases.size() << " cases, " << rays << " rays, generated in "
              << int(msSince(start)) << " ms\n";
    return cases;
}

// Brute force is the reference every other configuration is compared with, bit for bit.
BruteReference traceReference(const std::vector<StressCase>& cases, Tracer& tracer, Progress& progress) {
    BruteReference ref;
    const StressConfig brute = defaultStressConfig(Backend::Brute);
    double ms = 0.0;
    for (const StressCase& c : cases) {
        const auto start = Clock::now();
        ref.hits.push_back(traceStressCase(c, brute, tracer));
        ref.ms.push_back(msSince(start));
        ms += ref.ms.back();
        progress.step("brute " + c.name);
    }
    progress.note("brute-force reference traced in " + std::to_string(int(ms)) + " ms");
    return ref;
}

StressTally runCase(const StressCase& c, const StressConfig& config, const std::vector<RayHit>& reference,
                    double referenceMs, Tracer& tracer) {
    const bool isBrute = config.trace.backend == Backend::Brute;
    const auto start = Clock::now();
    StressTally t;
    try {
        const std::vector<RayHit> hits = isBrute ? reference : traceStressCase(c, config, tracer);
        t = tallyStressCase(c, hits, isBrute ? nullptr : &reference);
    } catch (const std::exception& e) {
        // A refusal is a result too: counted and shown, and the run goes on.
        t.cases = 1;
        t.rays = c.rays.size();
        t.errors = 1;
        t.examples.push_back(c.family + " / " + c.name + ": error: " + e.what());
    }
    t.traceMs = t.slowestMs = isBrute ? referenceMs : msSince(start);
    t.slowestCase = c.name;
    return t;
}

std::vector<StressRow> runConfigurations(const std::vector<StressConfig>& configs, const std::vector<std::string>& families,
                                         const std::vector<StressCase>& cases, const BruteReference& reference,
                                         Tracer& tracer, Progress& progress) {
    std::vector<StressRow> rows;
    for (const StressConfig& config : configs) {
        std::map<std::string, StressTally> byFamily;
        double ms = 0.0;
        for (std::size_t i = 0; i < cases.size(); ++i) {
            const StressTally t = runCase(cases[i], config, reference.hits[i], reference.ms[i], tracer);
            ms += t.traceMs;  // for brute force, the reference's own time
            byFamily[cases[i].family].add(t);
            progress.step(config.name + " " + cases[i].name);
        }
        progress.note(config.name + " traced in " + std::to_string(int(ms)) + " ms");
        for (const std::string& f : families) rows.push_back({config.name, config.isDefault, f, byFamily[f]});
    }
    return rows;
}

// Prints the table, the failures' examples and the determinism checks; returns whether every
// default configuration is clean and every check holds.
bool printReport(const std::vector<StressRow>& rows, const std::vector<DeterminismResult>& determinism,
                 const StressCommand& command, const Tracer& tracer) {
    bool ok = true;
    std::printf("%-38s %-12s %6s %9s %9s %6s %6s %9s %5s %6s %9s  %s\n", "configuration", "family", "cases", "rays",
                "must-hit", "leaks", "self", "!= brute", "ties", "errors", "ms", "slowest case (ms)");
    for (const StressRow& r : rows) {
        const bool bad = !r.tally.clean();
        if (bad && r.isDefault) ok = false;
        std::printf("%-38s %-12s %6llu %9llu %9llu %6llu %6llu %9llu %5llu %6llu %9.1f  %s (%.1f)%s\n",
                    (r.config + (r.isDefault ? " (default)" : "")).c_str(), r.family.c_str(),
                    (unsigned long long)r.tally.cases, (unsigned long long)r.tally.rays,
                    (unsigned long long)r.tally.mustHit, (unsigned long long)r.tally.leaks,
                    (unsigned long long)r.tally.selfIntersections, (unsigned long long)r.tally.mismatches,
                    (unsigned long long)r.tally.tieViolations, (unsigned long long)r.tally.errors, r.tally.traceMs,
                    r.tally.slowestCase.c_str(), r.tally.slowestMs, bad ? "  <-- FAILS" : "");
    }
    for (const StressRow& r : rows)
        for (const std::string& e : r.tally.examples) std::printf("  %s: %s\n", r.config.c_str(), e.c_str());
    if (!determinism.empty()) std::printf("\ndeterminism (%s):\n", determinismCase(command.size).name.c_str());
    for (const DeterminismResult& d : determinism) {
        if (!d.holds) ok = false;
        std::printf("  %-34s %s  %s\n", d.name.c_str(), d.holds ? "holds" : "FAILS", d.detail.c_str());
    }
    if (!tracer.device().empty() && command.validate) {
        std::printf("validation errors: %u\n", tracer.validationErrors());
        if (tracer.validationErrors() > 0) ok = false;
    }
    return ok;
}

void writeJson(const std::string& path, const std::vector<StressRow>& rows,
               const std::vector<DeterminismResult>& determinism, const StressCommand& command,
               const Tracer& tracer) {
    nlohmann::ordered_json j;
    j["seed"] = command.seed;
    j["size"] = command.size == StressSize::Large ? "large" : "small";
    if (!tracer.device().empty()) j["device"] = tracer.device();
    for (const StressRow& r : rows)
        j["rows"].push_back({{"configuration", r.config}, {"default", r.isDefault}, {"family", r.family},
                             {"cases", r.tally.cases}, {"rays", r.tally.rays}, {"must_hit", r.tally.mustHit},
                             {"leaks", r.tally.leaks}, {"self_intersections", r.tally.selfIntersections},
                             {"differ_from_brute", r.tally.mismatches},
                             {"tie_violations", r.tally.tieViolations}, {"errors", r.tally.errors},
                             {"ms", r.tally.traceMs}, {"slowest_case", r.tally.slowestCase},
                             {"slowest_case_ms", r.tally.slowestMs}, {"examples", r.tally.examples}});
    for (const DeterminismResult& d : determinism)
        j["determinism"].push_back({{"check", d.name}, {"holds", d.holds}, {"detail", d.detail}});
    writeFileAtomically(path, j.dump(2) + "\n");
}

// One tracer for every configuration, so that each switches to its options on the same
// threads, device and pipelines: made with the first backend that runs on the Vulkan device
// where one does (the device opens now, before any long work); without one, --device and
// --validate have nothing to choose and are left out, as stress always has.
Tracer openTracer(const StressCommand& command, const std::vector<Backend>& backends) {
    const auto vulkan = std::find_if(backends.begin(), backends.end(), runsOnVulkan);
    TracerOptions options;
    options.trace.backend = vulkan != backends.end() ? *vulkan : backends.front();
    if (vulkan != backends.end()) {
        options.device = command.device;
        options.validate = command.validate;
    }
    return Tracer(options);
}

}  // namespace

int runStressCommand(const StressCommand& command) {
    const std::vector<std::string> families = command.families.empty() ? stressFamilies() : command.families;
    const std::vector<Backend> backends = command.backends.empty()
                                              ? std::vector<Backend>{Backend::Brute, Backend::CpuSeq, Backend::Cpu, Backend::Gpu}
                                              : command.backends;
    checkOutputs({{"--json", command.jsonPath, OutputFormat::Text}}, {});
    const std::vector<StressCase> cases = generateCases(command, families);
    Tracer tracer = openTracer(command, backends);
    const std::vector<StressConfig> configs = stressConfigs(backends, command.withOptions);
    std::vector<StressRow> rows;
    {
        // A bar over every (configuration, case) pair and the reference, on a terminal; a line
        // per stage otherwise.
        Progress progress("dacrt stress", cases.size() * (configs.size() + 1));
        const BruteReference reference = traceReference(cases, tracer, progress);
        rows = runConfigurations(configs, families, cases, reference, tracer, progress);
    }
    std::vector<DeterminismResult> determinism;
    if (command.determinism) determinism = determinismChecks(backends, tracer, command.size);

    const bool ok = printReport(rows, determinism, command, tracer);
    if (!command.jsonPath.empty()) writeJson(command.jsonPath, rows, determinism, command, tracer);
    std::printf("%s\n", ok ? "stress: every default configuration is clean and every determinism check holds"
                           : "stress: FAILED (see the rows marked above)");
    if (!command.jsonPath.empty()) std::printf("stress: wrote %s\n", command.jsonPath.c_str());
    return ok ? kExitSuccess : kExitCheckFailed;
}

}  // namespace dacrt
