#pragma once
// The parts of a trace a backend times, one field per phase. A phase the backend does not
// run stays empty and is not reported (a phase that took no time is).
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace dacrt {

struct PhaseTimes {
    std::optional<double> bounds;           // the triangles' bounds and the scene's box (dacrt's backends, each frame)
    std::optional<double> makeRays;         // secondary rays made on the host from the primary hits
    std::optional<double> groupRays;        // cpu backends: a secondary pass's rays grouped (--ray-grouping)
    std::optional<double> skips;            // the triangle skips (dacrt's backends)
    std::optional<double> allocate;         // ray queries: the structure's buffers
    std::optional<double> divide;           // the parallel scheme's division (cpu, gpu)
    std::optional<double> upload;           // gpu, ray queries
    std::optional<double> build;            // ray queries, Embree: the structure built...
    std::optional<double> refit;            // ... or refitted
    std::optional<double> pipelineCompile;  // Vulkan pipelines made (first use): a cost of the process
    std::optional<double> step1;            // cpu
    std::optional<double> transfer;         // cpu: the transfer rounds
    std::optional<double> dispatch;         // gpu, ray queries
    std::optional<double> readback;         // gpu, ray queries
    std::optional<double> trace;            // Embree

    using Field = std::optional<double> PhaseTimes::*;

    // Adds ms to a phase (a phase run more than once in a trace or in a batched pass).
    static void addTo(std::optional<double>& phase, double ms) { phase = phase.value_or(0.0) + ms; }

    // Every phase of `other` added to this one's (batches of one pass).
    void add(const PhaseTimes& other) {
        for (std::size_t i = 0; i < kPhases.size(); ++i)
            if (other.*kPhases[i].second) addTo(this->*kPhases[i].second, *(other.*kPhases[i].second));
    }

    // The pipeline compilation within the trace (zero without one): render and bench take it
    // out of the frame's time.
    double compileMs() const { return pipelineCompile.value_or(0.0); }
    // The acceleration structure's build or refit (the peers).
    double structureMs() const { return build.value_or(0.0) + refit.value_or(0.0); }

    // f(name, field, ms) for every phase run, in the order of listed().
    template <class F>
    void forEach(F f) const {
        for (const auto& [name, field] : kPhases)
            if (this->*field) f(std::string(name), field, *(this->*field));
    }

    // The phases run, with their report names, in one order for every backend (the order they
    // run in): what --stats (trace_phases) and bench (parts_ms) print.
    std::vector<std::pair<std::string, double>> listed() const {
        std::vector<std::pair<std::string, double>> phases;
        forEach([&phases](const std::string& name, Field, double ms) { phases.emplace_back(name, ms); });
        return phases;
    }

private:
    static constexpr std::array<std::pair<const char*, Field>, 15> kPhases{{
        {"bounds", &PhaseTimes::bounds},
        {"make rays", &PhaseTimes::makeRays},
        {"group rays", &PhaseTimes::groupRays},
        {"skips", &PhaseTimes::skips},
        {"allocate", &PhaseTimes::allocate},
        {"divide", &PhaseTimes::divide},
        {"upload", &PhaseTimes::upload},
        {"build", &PhaseTimes::build},
        {"refit", &PhaseTimes::refit},
        {"pipeline compile", &PhaseTimes::pipelineCompile},
        {"step1", &PhaseTimes::step1},
        {"transfer", &PhaseTimes::transfer},
        {"dispatch", &PhaseTimes::dispatch},
        {"readback", &PhaseTimes::readback},
        {"trace", &PhaseTimes::trace},
    }};
};

}  // namespace dacrt
