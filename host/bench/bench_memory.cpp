#include "bench/bench_memory.hpp"

#include <algorithm>
#include <iostream>

#include "core/errors.hpp"
#include "core/process_memory.hpp"
#include "core/system_memory.hpp"
#include "bench/bench_configs.hpp"
#include "peers/embree_memory.hpp"

namespace dacrt {
namespace {

// The share of the machine's memory a run may hold: the rest is the system's and its caches'.
constexpr std::uint64_t kBudgetPercentOfMachine = 90;

// Which of a plan's buffers a configuration keeps from frame to frame: Embree's structure
// (its plan bounds it), and what a Vulkan backend holds on its device (on lavapipe, this
// machine's memory too); the rest is the frame's.
bool keptBetweenFrames(const BenchConfig& c, const std::string& buffer) {
    if (c.backend() == Backend::Embree) return buffer == kEmbreeStructurePlanLine;
    return runsOnVulkan(c.backend()) && !buffer.starts_with("host:");
}

ConfigMemory configMemory(const BenchConfig& c, const TraceScene& scene, const RayBatch& rays, BenchRun& run) {
    useConfig(run.tracer, c);
    ConfigMemory m;
    for (const FramePlan::Buffer& b : run.tracer.plan(scene, rays).memory)
        (keptBetweenFrames(c, b.name) ? m.kept : m.frame) += b.bytes;
    return m;
}

std::string bytesText(std::uint64_t bytes) { return std::to_string(bytes) + " bytes"; }

[[noreturn]] void refuse(const BenchMemoryPlan& plan, const std::string& label, const ConfigMemory& m,
                         const std::string& sceneName) {
    const std::uint64_t need = plan.held + m.kept + m.frame;
    throw InputError("bench: " + label + " on " + sceneName + " needs about " + bytesText(m.kept + m.frame) + " (" +
                     bytesText(m.kept) + " kept between its frames, " + bytesText(m.frame) + " per frame) beside the " +
                     bytesText(plan.held) + " this run holds, more than the " + bytesText(plan.budget) +
                     " a run may hold (" + plan.budgetOrigin + "; over by " + bytesText(need - plan.budget) +
                     "): bench fewer pixels (--size) or a smaller scene");
}

}  // namespace

std::uint64_t BenchMemoryPlan::allKept() const {
    std::uint64_t kept = 0, frame = 0;
    for (const ConfigMemory& m : configs) {
        kept += m.kept;
        frame = std::max(frame, m.frame);
    }
    return held + kept + frame;
}

std::uint64_t BenchMemoryPlan::largestAlone() const {
    std::uint64_t largest = 0;
    for (const ConfigMemory& m : configs) largest = std::max(largest, m.kept + m.frame);
    return held + largest;
}

void chooseHolding(BenchMemoryPlan& plan, const std::vector<std::string>& labels, const std::string& sceneName) {
    plan.oneAtATime = false;
    if (plan.budget == 0 || plan.allKept() <= plan.budget) return;
    for (std::size_t c = 0; c < plan.configs.size(); ++c)
        if (plan.held + plan.configs[c].kept + plan.configs[c].frame > plan.budget)
            refuse(plan, labels.at(c), plan.configs[c], sceneName);
    plan.oneAtATime = true;
}

BenchMemoryPlan planBenchMemory(const std::vector<BenchConfig>& configs, const TraceScene& scene, const Camera& camera,
                                const std::string& sceneName, const BenchCommand& cmd, BenchRun& run) {
    std::vector<Ray> buffer;
    const RayBatch frameRays =
        makeCameraRays(camera, cmd.width, cmd.height, run.pools.of(run.hardwareThreads), buffer);
    const std::uint64_t limitMiB = cmd.memoryLimitMiB;
    BenchMemoryPlan plan;
    const std::optional<ResidentMemory> resident = residentMemory();
    plan.held = resident ? resident->current : 0;
    plan.budget = limitMiB ? limitMiB << 20 : physicalMemoryBytes() / 100 * kBudgetPercentOfMachine;
    plan.budgetOrigin = limitMiB ? "--memory-limit " + std::to_string(limitMiB) + " MiB"
                                 : std::to_string(kBudgetPercentOfMachine) + "% of this machine's memory";
    std::vector<std::string> labels;
    for (const BenchConfig& c : configs) {
        plan.configs.push_back(configMemory(c, scene, frameRays, run));
        labels.push_back(configLabel(c));
    }
    chooseHolding(plan, labels, sceneName);
    return plan;
}

std::string keptAtOnceText(const BenchMemoryPlan& plan) {
    return "every configuration's kept state at once would need about " + bytesText(plan.allKept()) +
           " with what the run holds, more than the " + bytesText(plan.budget) + " it may hold (" + plan.budgetOrigin +
           ")";
}

std::string oneAtATimeNotice(const BenchMemoryPlan& plan, const std::string& sceneName) {
    return "dacrt bench: " + sceneName + ": " + keptAtOnceText(plan) + ", so the configurations run one after " +
           "another, not interleaved: each one's structure is made before its frames (untimed) and freed before " +
           "the next one's (at most " + bytesText(plan.largestAlone()) + ")";
}

BenchMemoryPlan planSceneMemory(const std::vector<BenchConfig>& configs, const BenchScene& scene,
                                const BenchCommand& cmd, BenchRun& run) {
    const BenchMemoryPlan plan = planBenchMemory(configs, scene.traced, scene.cameras.front(), scene.name, cmd, run);
    if (plan.oneAtATime) std::cerr << oneAtATimeNotice(plan, scene.name) << "\n";
    return plan;
}

std::vector<std::pair<int, std::size_t>> frameOrder(int repeats, std::size_t configs, bool oneAtATime) {
    std::vector<std::pair<int, std::size_t>> order;
    for (int w = 0; w < repeats; ++w)
        for (std::size_t c = 0; c < configs; ++c) order.emplace_back(w, c);
    if (oneAtATime)
        std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    return order;
}

void KeptStates::prepareAll(const std::vector<BenchConfig>& configs, const TraceScene& scene, BenchRun& run) {
    if (configs.size() != embree_.size()) throw InternalError("KeptStates: one InLoopEmbree per configuration");
    if (oneAtATime_) return;
    for (std::size_t c = 0; c < configs.size(); ++c) prepareStructure(run, configs[c], scene, *embree_[c]);
}

void KeptStates::hold(std::size_t c, const BenchConfig& config, const TraceScene& scene, BenchRun& run) {
    if (!oneAtATime_ || held_ == c) return;
    for (InLoopEmbree* e : embree_) e->release();
    run.tracer.releaseKept();
    prepareStructure(run, config, scene, *embree_[c]);
    held_ = c;
}

}  // namespace dacrt
