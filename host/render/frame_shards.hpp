#pragma once
// Which frames of a range this process renders: the I-th of N shards, from --shard I/N, a Slurm
// job array (SLURM_ARRAY_TASK_ID, _COUNT, _MIN, _STEP) or a Kubernetes Indexed Job
// (JOB_COMPLETION_INDEX with --shard-count N), interleaved (frame k of the range to shard
// k mod N) or blocked (contiguous runs whose sizes differ by one at most).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "render/frame_range.hpp"

namespace dacrt {

enum class ShardMode { Interleaved, Blocked };

constexpr int kMaxShards = 1'000'000;

// What the command line says about shards.
struct ShardRequest {
    std::string shard;  // --shard I/N; empty: none
    int count = 0;      // --shard-count N (with JOB_COMPLETION_INDEX); 0: not given
    ShardMode mode = ShardMode::Interleaved;
    bool modeGiven = false;  // --shard-mode was named
};

struct Shard {
    int index = 0;
    int count = 1;
    ShardMode mode = ShardMode::Interleaved;
    std::string source;  // where index and count came from, for the stderr line
};

// Checks the options alone (before the environment is read): a well-formed --shard, no --shard
// together with --shard-count, and no shard option without a frame range. Throws InputError.
void checkShardRequest(const ShardRequest& request, bool frameRange);

// Reads an environment variable; null when unset (std::getenv in the command).
using EnvironmentLookup = std::function<const char*(const char*)>;

// The shard this process renders: --shard, else a Slurm array task, else a Kubernetes Indexed
// Job's index (only for a frame range); a whole range (0/1, source empty) when none applies.
// Throws InputError on a variable or option that does not make a shard, saying which and why.
Shard resolveShard(const ShardRequest& request, bool frameRange, const EnvironmentLookup& environment);

// The frame numbers of `range` that `shard` renders, in order.
std::vector<std::int64_t> shardFrames(const FrameRange& range, const Shard& shard);

// "1, 5, 9" or "1, 5, 9, ... 97 (25 frames)": a shard's frames for the stderr line.
std::string describeFrames(const std::vector<std::int64_t>& frames);

std::string toString(ShardMode mode);

}  // namespace dacrt
