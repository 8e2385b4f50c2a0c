#include "render/frame_shards.hpp"

#include <optional>

#include "core/errors.hpp"

namespace dacrt {
namespace {

// A non-negative integer of at most 9 digits, the whole text; none otherwise.
std::optional<std::int64_t> count(const std::string& text) {
    if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos)
        return std::nullopt;
    return std::stoll(text);
}

Shard parseShardOption(const std::string& text) {
    const std::size_t slash = text.find('/');
    const std::optional<std::int64_t> i = slash == std::string::npos ? std::nullopt : count(text.substr(0, slash));
    const std::optional<std::int64_t> n = slash == std::string::npos ? std::nullopt : count(text.substr(slash + 1));
    if (!i || !n) throw InputError("--shard " + text + ": a shard is I/N, the I-th of N (I from 0 to N-1), like 0/4");
    if (*n < 1 || *n > kMaxShards)
        throw InputError("--shard " + text + ": the number of shards must lie in 1.." + std::to_string(kMaxShards));
    if (*i >= *n) throw InputError("--shard " + text + ": shards are numbered from 0 to " + std::to_string(*n - 1));
    return Shard{int(*i), int(*n), ShardMode::Interleaved, "--shard " + text};
}

// An environment variable that must be a non-negative integer when set.
std::optional<std::int64_t> integerVariable(const EnvironmentLookup& environment, const char* name) {
    const char* value = environment(name);
    if (!value) return std::nullopt;
    const std::optional<std::int64_t> n = count(value);
    if (!n) throw InputError(std::string(name) + "='" + value + "' is not a non-negative integer");
    return n;
}

Shard slurmShard(const EnvironmentLookup& environment, std::int64_t id) {
    const std::optional<std::int64_t> n = integerVariable(environment, "SLURM_ARRAY_TASK_COUNT");
    if (!n || *n < 1 || *n > kMaxShards)
        throw InputError("SLURM_ARRAY_TASK_ID=" + std::to_string(id) +
                         " is set but SLURM_ARRAY_TASK_COUNT is not a number of tasks from 1 to " +
                         std::to_string(kMaxShards) + ", so the number of shards is unknown (give --shard I/N)");
    if (const std::optional<std::int64_t> step = integerVariable(environment, "SLURM_ARRAY_TASK_STEP");
        step && *step != 1)
        throw InputError("SLURM_ARRAY_TASK_STEP=" + std::to_string(*step) +
                         ": the array's task ids skip, so they do not number shards 0..N-1; submit a contiguous "
                         "array (--array=0-" +
                         std::to_string(*n - 1) + ") or give --shard I/N");
    const std::int64_t min = integerVariable(environment, "SLURM_ARRAY_TASK_MIN").value_or(0);
    std::string source = "SLURM_ARRAY_TASK_ID=" + std::to_string(id);
    if (environment("SLURM_ARRAY_TASK_MIN")) source += " - SLURM_ARRAY_TASK_MIN=" + std::to_string(min);
    source += ", SLURM_ARRAY_TASK_COUNT=" + std::to_string(*n);
    if (id < min || id - min >= *n)
        throw InputError(source + ": task " + std::to_string(id - min) + " is not one of 0.." + std::to_string(*n - 1) +
                         "; the array's ids must be contiguous (--array=A-B, no list or step), or give --shard I/N");
    return Shard{int(id - min), int(*n), ShardMode::Interleaved, source};
}

Shard kubernetesShard(const ShardRequest& request, std::int64_t index) {
    if (request.count == 0)
        throw InputError(
            "JOB_COMPLETION_INDEX=" + std::to_string(index) +
            " is set (a Kubernetes Indexed Job) but the number of shards is not: pass --shard-count N, the "
            "Job's completions");
    if (index >= request.count)
        throw InputError("JOB_COMPLETION_INDEX=" + std::to_string(index) + " is not below --shard-count " +
                         std::to_string(request.count) + ": --shard-count must equal the Job's completions");
    return Shard{int(index), request.count, ShardMode::Interleaved,
                 "JOB_COMPLETION_INDEX=" + std::to_string(index) + ", --shard-count " + std::to_string(request.count)};
}

}  // namespace

std::string toString(ShardMode mode) { return mode == ShardMode::Blocked ? "blocked" : "interleaved"; }

void checkShardRequest(const ShardRequest& request, bool frameRange) {
    if (!frameRange && (!request.shard.empty() || request.count || request.modeGiven))
        throw InputError(std::string(!request.shard.empty() ? "--shard"
                                     : request.count        ? "--shard-count"
                                                            : "--shard-mode") +
                         " splits a frame range over several runs: give --frames FIRST:LAST");
    if (!request.shard.empty() && request.count)
        throw InputError("--shard " + request.shard +
                         " already says the number of shards; --shard-count is for a "
                         "Kubernetes Indexed Job, whose JOB_COMPLETION_INDEX gives the index");
    if (request.count < 0 || request.count > kMaxShards)
        throw InputError("--shard-count " + std::to_string(request.count) + ": the number of shards must lie in 1.." +
                         std::to_string(kMaxShards));
    if (!request.shard.empty()) parseShardOption(request.shard);
}

Shard resolveShard(const ShardRequest& request, bool frameRange, const EnvironmentLookup& environment) {
    checkShardRequest(request, frameRange);
    Shard shard;
    if (!frameRange) return shard;  // one instant: an array task renders it whole
    if (!request.shard.empty()) {
        shard = parseShardOption(request.shard);
    } else if (const std::optional<std::int64_t> id = integerVariable(environment, "SLURM_ARRAY_TASK_ID")) {
        if (request.count)
            throw InputError(
                "--shard-count is for a Kubernetes Indexed Job, but this is a Slurm array task "
                "(SLURM_ARRAY_TASK_ID is set; SLURM_ARRAY_TASK_COUNT gives the count)");
        shard = slurmShard(environment, *id);
    } else if (const std::optional<std::int64_t> index = integerVariable(environment, "JOB_COMPLETION_INDEX")) {
        shard = kubernetesShard(request, *index);
    } else if (request.count) {
        throw InputError("--shard-count " + std::to_string(request.count) +
                         " gives the number of shards of a Kubernetes Indexed Job, but JOB_COMPLETION_INDEX is not set "
                         "(outside one, give --shard I/N)");
    }
    shard.mode = request.mode;
    return shard;
}

std::vector<std::int64_t> shardFrames(const FrameRange& range, const Shard& shard) {
    const std::int64_t m = range.count(), n = shard.count, i = shard.index;
    std::vector<std::int64_t> frames;
    if (shard.mode == ShardMode::Interleaved) {
        for (std::int64_t k = i; k < m; k += n) frames.push_back(range.frameAt(k));
        return frames;
    }
    // Blocked: the first m mod n shards take one frame more, so sizes differ by one at most.
    const std::int64_t base = m / n, extra = m % n;
    const std::int64_t begin = i * base + std::min(i, extra);
    const std::int64_t size = base + (i < extra ? 1 : 0);
    for (std::int64_t k = begin; k < begin + size; ++k) frames.push_back(range.frameAt(k));
    return frames;
}

std::string describeFrames(const std::vector<std::int64_t>& frames) {
    constexpr std::size_t kShown = 8;
    std::string out;
    for (std::size_t k = 0; k < frames.size() && k < kShown; ++k) out += (k ? ", " : "") + std::to_string(frames[k]);
    if (frames.size() > kShown) out += ", ... " + std::to_string(frames.back());
    return out + " (" + std::to_string(frames.size()) + (frames.size() == 1 ? " frame)" : " frames)");
}

}  // namespace dacrt
