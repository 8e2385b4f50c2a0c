#pragma once
// What `dacrt bench --suite animation` reports: per frame and per configuration the phases
// (evaluate, prepare, build or refit, trace, the backend's work, the total), their mean, min
// and max over the frames, the rays per second and the hits' differences from cpu-seq's; as
// tables on stdout, a CSV and a JSON.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <dacrt/tracer.hpp>

#include "bench/bench.hpp"
#include "bench/bench_rows.hpp"

namespace dacrt {

struct PhaseStats {
    double mean = 0.0, min = 0.0, max = 0.0;
};

// A configuration's frames of one scene, summed up.
struct AnimationSummary {
    std::string scene;
    BenchConfig config;
    std::size_t frames = 0;
    std::size_t rays = 0;  // per frame
    PhaseStats triangles, evaluate, prepare, trace, work, total, mrays;
    std::optional<PhaseStats> build;        // the peers
    std::optional<PhaseStats> copy;         // the peers' vertex copy, not counted
    std::optional<double> initialBuildMs;   // the refit peers' first structure, before the frames
    std::uint64_t differing = 0, nearTies = 0, realErrors = 0;  // summed over the frames
    std::size_t rebuilds = 0;               // frames a refit peer rebuilt for
    bool exactRequired = false;
    // cpu's mean work (total) over this configuration's: above 1, cpu is slower. Absent without
    // a cpu row.
    std::optional<double> cpuWorkRatio, cpuTotalRatio;
};

std::vector<AnimationSummary> summarizeAnimation(const std::vector<AnimationFrameRow>& rows);

void printAnimationTables(const BenchCommand& cmd, const std::vector<AnimationScene>& scenes,
                          const std::vector<AnimationFrameRow>& rows);

void writeAnimationOutputs(const BenchCommand& cmd, const std::vector<AnimationScene>& scenes,
                           const std::vector<AnimationFrameRow>& rows, const Tracer& tracer, unsigned hardwareThreads);

}  // namespace dacrt
