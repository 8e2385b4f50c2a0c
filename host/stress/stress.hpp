#pragma once
// Runs the stress cases through the backends: leaks, self-intersections, disagreements with
// brute force and tie-rule violations per configuration; the determinism checks; the `dacrt
// stress` command.
#include <cstdint>
#include <string>
#include <vector>

#include "library/backend_dispatcher.hpp"
#include "stress/stress_cases.hpp"

namespace dacrt {

struct StressConfig {
    std::string name;  // as the render command line would say it
    bool isDefault = false;
    BackendRequest request;
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

// A case's frame; `bounds` receives the triangle bounds and must outlive the frame.
FrameGeometry stressGeometry(const StressCase& c, std::vector<Bounds>& bounds);

std::vector<Hit> traceStressCase(const StressCase& c, const StressConfig& config, BackendDispatcher& backends);

// One backend's hits of one case against the case's marks and (unless null) the brute-force
// hits of the same rays.
StressTally tallyStressCase(const StressCase& c, const std::vector<Hit>& hits, const std::vector<Hit>* reference);

struct DeterminismResult {
    std::string name;
    bool holds = false;
    std::string detail;
};

// The same hits bit for bit across 10 runs, across thread counts and across region counts
// 1 to 64, for each given backend, all equal to brute force.
std::vector<DeterminismResult> determinismChecks(const std::vector<Backend>& backends, BackendDispatcher& dispatcher,
                                                 StressSize size);

struct StressCommand {
    std::vector<std::string> families;  // empty: all
    std::vector<Backend> backends;      // empty: brute, cpu-seq, cpu and gpu
    StressSize size = StressSize::Large;
    bool withOptions = true;
    bool determinism = true;
    std::uint64_t seed = 1;
    DeviceChoice devices;  // gpu
    std::string jsonPath;
};

// Prints one table row per configuration and family, then the determinism checks. Returns 0
// when every default configuration is clean and every determinism check holds, 1 otherwise.
int runStressCommand(const StressCommand& command);

}  // namespace dacrt
