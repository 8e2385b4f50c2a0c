#pragma once
// `dacrt bench --suite animation`: the per-frame cost of an animated scene. Each frame's
// animation is evaluated once (GltfDocument::scene at the frame's time: its own phase, the same
// for every backend), then every configuration does its frame's work on it, interleaved as
// every suite is: each configuration makes its rays and traces on the run's Tracer, where dacrt's
// backends compute the triangles' bounds and trace, and the peers rebuild or refit the structure
// they keep across frames and trace (animated_frame.hpp). Each frame's primary hits are checked
// against cpu-seq's, which every dacrt backend must match bit for bit.
#include <vector>

#include "bench/bench.hpp"
#include "bench/bench_frame.hpp"
#include "bench/bench_rows.hpp"

namespace dacrt {

// `configs`: cpu-seq's default first (the reference). Prints the tables, writes the CSV and
// JSON, and returns the exit code: kExitCheckFailed when a dacrt backend's hits differ from
// cpu-seq's, else the validation epilogue's.
int runAnimationSuite(const BenchCommand& cmd, const std::vector<BenchConfig>& configs, BenchRun& run);

}  // namespace dacrt
