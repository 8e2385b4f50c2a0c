#pragma once
// Runs the stress cases through the backends of the public Tracer (include/dacrt/): leaks,
// self-intersections, disagreements with brute force and tie-rule violations per
// configuration; the determinism checks; the `dacrt stress` command.
#include <cstdint>
#include <string>
#include <vector>

#include <dacrt/tracer.hpp>

#include "stress/stress_cases.hpp"

namespace dacrt {

struct StressConfig {
    std::string name;  // as the render command line would say it
    bool isDefault = false;
    TraceOptions trace;
    GpuTuning gpu;
};

// A backend's default configuration, named as the backend.
StressConfig defaultStressConfig(Backend backend);

// The default configuration of each backend, then, with options, every non-default value
// of the options that could change which triangles a ray is tested against.
std::vector<StressConfig> stressConfigs(const std::vector<Backend>& backends, bool withOptions);

struct StressTally {
    std::uint64_t cases = 0;
    std::uint64_t rays = 0;
    std::uint64_t mustHit = 0;
    std::uint64_t leaks = 0;              // a must-hit ray that reported a miss
    std::uint64_t selfIntersections = 0;  // a hit on a triangle the ray's surface start rules out
    std::uint64_t mismatches = 0;         // hit differs from brute force in any bit (any hit: visibility)
    std::uint64_t tieViolations = 0;      // a coincident group answered by other than its lowest id
    std::uint64_t errors = 0;             // cases the backend refused or failed with an error
    double traceMs = 0.0;
    double slowestMs = 0.0;   // the slowest case: where a pathology would show
    std::string slowestCase;
    std::vector<std::string> examples;  // the first few failures, described

    void add(const StressTally& o);
    bool clean() const {
        return leaks == 0 && selfIntersections == 0 && mismatches == 0 && tieViolations == 0 && errors == 0;
    }
};

// The case's closest hits (any hits for HitQuery::Any) with the configuration's options, on
// the tracer's threads and device: its triangles and rays as the public API's arrays, each
// ray bit for bit the case's (DirectionLength::AsGiven).
std::vector<RayHit> traceStressCase(const StressCase& c, const StressConfig& config, Tracer& tracer);

// One backend's hits of one case against the case's marks and (unless null) the brute-force
// hits of the same rays.
StressTally tallyStressCase(const StressCase& c, const std::vector<RayHit>& hits, const std::vector<RayHit>* reference);

struct DeterminismResult {
    std::string name;
    bool holds = false;
    std::string detail;
};

// The same hits bit for bit across 10 runs, across thread counts and across region counts
// 1 to 64, for each given backend, all equal to brute force. gpu is left out where the tracer
// opened no device.
std::vector<DeterminismResult> determinismChecks(const std::vector<Backend>& backends, Tracer& tracer, StressSize size);

struct StressCommand {
    std::vector<std::string> families;  // empty: all
    std::vector<Backend> backends;      // empty: brute, cpu-seq, cpu and gpu
    StressSize size = StressSize::Large;
    bool withOptions = true;
    bool determinism = true;
    std::uint64_t seed = 1;
    std::string device;     // gpu, rayquery: --device
    bool validate = false;  // gpu, rayquery: --validate
    std::string jsonPath;
};

// Prints one table row per configuration and family, then the determinism checks. Returns 0
// when every default configuration is clean and every determinism check holds, 1 otherwise.
int runStressCommand(const StressCommand& command);

}  // namespace dacrt
