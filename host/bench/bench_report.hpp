#pragma once
// What a bench run reports: the Pareto fronts, the table on stdout, the CSV and the JSON.
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dacrt/tracer.hpp>

#include "bench/bench.hpp"
#include "bench/bench_rows.hpp"

namespace dacrt {

// A configuration is dominated when another one of its series has no more error and is
// faster by more than this fraction, or has less error and is no slower. The same
// configuration measured in two runs on this machine differs by up to about 5%
// (docs/benchmarks.md), so closer times are a draw.
constexpr double kParetoTimeMargin = 0.05;

void markPareto(std::vector<BenchRow>& rows);
// What every run's JSON opens with: the command, the machine (CPU, SIMD target, the Tracer's
// device and driver) and the validation error count.
nlohmann::ordered_json runJson(const BenchCommand& cmd, const Tracer& tracer, unsigned hardwareThreads);
// Under --validate: every validation message of the run's device; true when there were errors
// (the command then fails with its validation exit code).
bool reportValidationErrors(const Tracer& tracer, std::ostream& err);
nlohmann::ordered_json rowJson(const BenchRow& r);
void writeCsv(const std::string& path, const std::vector<BenchRow>& rows);
// A header line of `columns`, then per row its value of each (strings quoted where they hold
// a comma or a quote; null as nothing).
void writeCsvOf(const std::string& path, const std::vector<std::string>& columns,
                const std::vector<nlohmann::ordered_json>& rows);
void printSummary(const std::vector<BenchRow>& rows);

}  // namespace dacrt
