#pragma once
// `dacrt bench --suite passes`: a lit frame's passes timed apart (the primary pass, a shadow
// pass per light, the occlusion pass), per configuration, interleaved as every suite is; each
// pass's answers checked slot by slot against cpu-seq's, which every dacrt backend must match.
// The passes are those of render (Tracer::traceFrame with the public FramePass list).
#include <vector>

#include "bench/bench.hpp"
#include "bench/bench_frame.hpp"
#include "bench/bench_rows.hpp"

namespace dacrt {

// Measures every scene of the command with `configs` (cpu-seq's default first: the reference),
// prints the table, writes the CSV and JSON, and returns the exit code: kExitCheckFailed when a
// dacrt backend's pass differs from cpu-seq's, else the validation epilogue's.
int runPassesSuite(const BenchCommand& cmd, const std::vector<BenchConfig>& configs, BenchRun& run);

}  // namespace dacrt
