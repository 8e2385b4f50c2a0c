#pragma once
// The configurations a bench run measures.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_rows.hpp"

namespace dacrt {

// The name of the embree rows whose rays are made and stored first, then traced through the
// Tracer (BenchConfig::raysInLoop false), beside each build mode's default.
inline constexpr const char* kStoredRays = "stored rays";

// The configuration as the summaries name it: its series, then its name unless "default".
std::string configLabel(const BenchConfig& c);

// The options of a configuration in full, as the CSV and JSON record them.
std::string optionText(const BenchConfig& c);

// The configuration's fields of a JSON row, in every suite's order: backend, series, config,
// default, options, threads.
void recordConfig(nlohmann::ordered_json& row, const BenchConfig& c);

// A backend's default configuration on hardwareThreads threads (cpu-seq: one).
BenchConfig baseConfig(Backend b, unsigned hardwareThreads);

// sweep: the backend's default, then each option value changed one at a time.
std::vector<BenchConfig> sweepConfigs(Backend b, unsigned hardwareThreads, unsigned gpuDefaultRegions,
                                      std::uint32_t gpuDefaultRayGroups, std::uint32_t gpuDefaultLeafBalance);

// peers: each DACRT backend's default against every mode of the peers (embree, rayquery):
// the quick, fair comparison, in one run.
std::vector<BenchConfig> peerConfigs(Backend b, unsigned hardwareThreads);

// skips: each DACRT backend's default, then each skip of the work plan off alone, then all
// off; the peers' defaults beside them.
std::vector<BenchConfig> skipConfigs(Backend b, unsigned hardwareThreads);

// passes: each DACRT backend's default and each build mode of the peers (their defaults
// otherwise), as the peers suite configures them; for embree also each mode's stored-ray row.
std::vector<BenchConfig> passesConfigs(Backend b, unsigned hardwareThreads);

// animation: each DACRT backend's default, and each peer's per-frame modes with their defaults
// otherwise: embree dynamic (a new BVH each frame) and refit, rayquery dynamic (rebuilt) and
// refit (updated). No static structure: it cannot follow moving vertices, and building one
// each frame would be the dynamic row at a slower build quality.
std::vector<BenchConfig> animationConfigs(Backend b, unsigned hardwareThreads);

// The source's Table 5.1 (threads, and two regions per thread) and Figure 5.3 (division axes).
std::vector<BenchConfig> table51Configs(Backend b, unsigned hardwareThreads);

}  // namespace dacrt
