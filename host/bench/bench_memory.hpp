#pragma once
// What a bench run holds at once over a scene, planned before its first frame. Each
// configuration keeps state between its frames, as its users keep it (the peers' structures,
// the gpu's resident triangles and buffers), and the configurations interleave within every
// repeat, so by default the run holds every configuration's state at once. Where that does not
// fit this machine's memory beside what the run already holds, the configurations run one after
// another instead, each one's state made before its frames (untimed) and freed before the next
// one's; where even one configuration does not fit, the run is refused before its first frame,
// with the numbers.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_frame.hpp"
#include "bench/bench_rows.hpp"
#include "bench/in_loop_embree.hpp"

namespace dacrt {

struct ConfigMemory {
    std::uint64_t kept = 0;   // held from one of its frames to the next
    std::uint64_t frame = 0;  // allocated by one frame and freed after it
};

struct BenchMemoryPlan {
    std::uint64_t held = 0;    // what the run holds already: the scene, its arrays (resident now)
    std::uint64_t budget = 0;  // the most the run may hold (0: unknown)
    std::string budgetOrigin;  // what set it: "--memory-limit" or the machine's share
    std::vector<ConfigMemory> configs;
    bool oneAtATime = false;

    // Every configuration's kept state, and the largest frame beside it.
    std::uint64_t allKept() const;
    // The largest one configuration holds alone (its kept state and its frame).
    std::uint64_t largestAlone() const;
};

// The memory each configuration keeps and each frame needs, for frames of the camera's rays at
// the command's size over `scene`, by its plan (Tracer::plan: what Embree's structure takes by
// its bound, what a Vulkan backend holds on its device, are kept), against a budget of the
// command's --memory-limit (0: 90% of this machine's memory).
// Throws InputError, before any frame, where one configuration alone exceeds the budget;
// `sceneName` names the scene in it.
BenchMemoryPlan planBenchMemory(const std::vector<BenchConfig>& configs, const TraceScene& scene, const Camera& camera,
                                const std::string& sceneName, const BenchCommand& cmd, BenchRun& run);

// Where the configurations' kept state goes, from the plan's figures: every one at once where
// it all fits the budget, else one at a time (oneAtATime set); throws InputError naming the
// configuration that does not fit alone. `labels` name the configurations.
void chooseHolding(BenchMemoryPlan& plan, const std::vector<std::string>& labels, const std::string& sceneName);

// "every configuration's kept state at once would need about N bytes ... more than ...".
std::string keptAtOnceText(const BenchMemoryPlan& plan);

// The line the run prints where its configurations run one after another, with the numbers.
std::string oneAtATimeNotice(const BenchMemoryPlan& plan, const std::string& sceneName);

// The plan over a loaded scene, for frames of its first camera at the command's size; prints
// oneAtATimeNotice where its configurations run one after another.
BenchMemoryPlan planSceneMemory(const std::vector<BenchConfig>& configs, const BenchScene& scene,
                                const BenchCommand& cmd, BenchRun& run);

// The order of one camera's frames: (repeat, configuration) pairs, the configurations
// interleaved within every repeat, or one configuration's repeats after another's.
std::vector<std::pair<int, std::size_t>> frameOrder(int repeats, std::size_t configs, bool oneAtATime);

// The configurations' kept state under a plan: every configuration's structure made before
// the first frame, or (one at a time) each made before its own frames and every other's freed.
class KeptStates {
public:
    KeptStates(bool oneAtATime, std::vector<InLoopEmbree*> embree) : oneAtATime_(oneAtATime), embree_(std::move(embree)) {}

    // Before the first frame: every configuration's structure (prepareStructure), unless they
    // are made one at a time.
    void prepareAll(const std::vector<BenchConfig>& configs, const TraceScene& scene, BenchRun& run);

    // Before a frame of configuration c: one at a time, where c's state is not the one held,
    // every kept state is freed and c's structure made.
    void hold(std::size_t c, const BenchConfig& config, const TraceScene& scene, BenchRun& run);

    bool oneAtATime() const { return oneAtATime_; }

private:
    bool oneAtATime_ = false;
    std::vector<InLoopEmbree*> embree_;  // each configuration's, by index
    std::optional<std::size_t> held_;
};

}  // namespace dacrt
