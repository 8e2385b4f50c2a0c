#pragma once
// The bench command: frame time against error for every backend and option value, measured
// against the float64 reference (docs/benchmarks.md).
#include <string>
#include <vector>

#include <dacrt/backend_tuning.hpp>
#include <dacrt/options.hpp>

#include "core/camera.hpp"
#include "core/enum_names.hpp"
#include "library/pass_options.hpp"
#include "render/frame_range.hpp"

namespace dacrt {

// sweep: every backend's default, then each option value changed one at a time.
// peers: each DACRT default against every mode of the peers (embree, rayquery).
// table51: the source's Table 5.1 and Figure 5.3 (threads, regions per thread, axes).
// passes: a lit frame's passes (primary, a shadow pass per light, occlusion) timed apart, for
// each DACRT default and every build mode of the peers, each pass's visibility checked against
// cpu-seq's.
// animation: the per-frame cost of an animated scene over a range of frames: the animation
// evaluated, then each DACRT default's prepare and trace, each peer's rebuild or refit and
// trace (bench_animation.hpp).
enum class BenchSuite { Sweep, Peers, Skips, Table51, Passes, Animation };

template <>
struct EnumNames<BenchSuite> {
    static constexpr std::array<std::pair<BenchSuite, std::string_view>, 6> table{{{BenchSuite::Sweep, "sweep"},
                                                                                    {BenchSuite::Peers, "peers"},
                                                                                    {BenchSuite::Skips, "skips"},
                                                                                    {BenchSuite::Table51, "table51"},
                                                                                    {BenchSuite::Passes, "passes"},
                                                                                    {BenchSuite::Animation, "animation"}}};
};

struct BenchCommand {
    std::vector<std::string> scenes;
    std::vector<Backend> backends;  // empty: cpu-seq, cpu, gpu (when a device exists), embree
    BenchSuite suite = BenchSuite::Sweep;
    int orbit = 1;
    CameraOptions camera;      // the base camera (the orbit's first); orbit is taken from `orbit`
    int width = 640;
    int height = 480;
    int repeat = 3;
    int warmup = 1;
    // Outputs; an empty path means outDir/bench.csv, outDir/bench.json. tools/bench/plot.py
    // draws the JSON.
    std::string outDir = "dacrt-bench";
    std::string csvPath;
    std::string jsonPath;
    std::string cacheDir;      // empty: $XDG_CACHE_HOME/dacrt or ~/.cache/dacrt
    bool useCache = true;
    std::string device;        // gpu, rayquery: --device (index or part of the name; empty: the best)
    bool validate = false;     // gpu, rayquery: --validate
    GpuProfile gpuProfile = GpuProfile::Auto;  // gpu: --gpu-profile, every configuration's
    // The most memory the run may hold, in MiB (--memory-limit; 0: 90% of this machine's):
    // configurations whose kept state does not fit at once run one after another
    // (bench/bench_memory.hpp).
    std::uint64_t memoryLimitMiB = 0;
    // --suite passes: the lights (render's --light) and the occlusion rays per hit (--ao).
    PassOptions passes{.lights = {}, .occlusionSamples = 4, .occlusionDistance = 0.0};
    // --suite animation: frames first..last (--frames, render's syntax), frame n at n / fps
    // seconds, of one animation or (empty) every one together (--animation).
    struct Animation {
        FrameRange frames{.first = 0, .last = 11, .step = 1};
        double fps = kDefaultFps;
        std::string animation;
    } animation;
};

// Returns the process exit code; throws InputError on bad input.
int runBenchCommand(const BenchCommand& command);

}  // namespace dacrt
