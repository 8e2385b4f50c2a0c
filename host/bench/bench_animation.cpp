#include "bench/bench_animation.hpp"

#include <algorithm>
#include <bit>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>

#include "bench/animated_frame.hpp"
#include "bench/animation_report.hpp"
#include "bench/bench_frame.hpp"
#include "bench/bench_memory.hpp"
#include "bench/bench_report.hpp"
#include "app/exit_codes.hpp"
#include "app/progress.hpp"
#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/timing.hpp"
#include "oracle/error_metrics.hpp"

namespace dacrt {
namespace {

std::string animationText(const GltfAnimationInfo& a, std::size_t index) {
    std::ostringstream s;
    s << (a.name.empty() ? "#" + std::to_string(index) : a.name) << " (" << a.start << "-" << a.end << " s)";
    return s.str();
}

// A configuration's timed runs of the current frame.
struct FrameRuns {
    std::vector<AnimatedWork> runs;
    std::uint64_t differing = 0, nearTies = 0, realErrors = 0;
};

// Compares a configuration's hits with cpu-seq's: dacrt's backends primitive and depth bit for
// bit; a peer's differing primitives split into near ties and real errors.
void checkHits(const std::vector<Hit>& reference, const std::vector<Hit>& hits, bool exact, const Scene& frame,
               const std::vector<Bounds>& bounds, const std::vector<Ray>& rays, ThreadPool& pool, FrameRuns& out) {
    if (reference.size() != hits.size())
        throw InternalError("bench: a backend answered " + std::to_string(hits.size()) + " rays, cpu-seq " +
                            std::to_string(reference.size()));
    if (exact) {
        for (std::size_t i = 0; i < hits.size(); ++i)
            out.differing += reference[i].prim != hits[i].prim ||
                             std::bit_cast<std::uint32_t>(reference[i].t) != std::bit_cast<std::uint32_t>(hits[i].t);
        return;
    }
    std::vector<ReferenceHit> asReference(reference.size());
    for (std::size_t i = 0; i < reference.size(); ++i)
        asReference[i] = ReferenceHit{reference[i].prim == kMissPrim ? std::numeric_limits<double>::infinity() : double(reference[i].t), reference[i].prim};
    const std::vector<std::uint8_t> unshaded(3 * rays.size(), 0);  // the shading error is not measured here
    const ErrorMetrics e = measureErrors(frame.triangles, bounds, rays, asReference, hits, unshaded, unshaded, pool);
    out.differing += e.differingPrim;
    out.nearTies += e.nearTies;
    out.realErrors += e.realErrors;
}

// The run whose work time is the median of the frame's runs (the lower one of an even count).
const AnimatedWork& medianRun(const std::vector<AnimatedWork>& runs) {
    std::vector<std::size_t> order(runs.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return runs[a].workMs < runs[b].workMs; });
    return runs[order[(order.size() - 1) / 2]];
}

// The suite keeps every configuration's structure from frame to frame (a refit follows the
// frame before it), so a run whose kept state does not fit at once is refused before its first
// frame (bench_memory.hpp) instead of holding one at a time.
void checkAnimationMemory(const std::vector<BenchConfig>& configs, const TraceScene& scene, const Camera& camera,
                          const BenchCommand& cmd, const std::string& name, BenchRun& run) {
    const BenchMemoryPlan plan = planBenchMemory(configs, scene, camera, name, cmd, run);
    if (plan.oneAtATime)
        throw InputError("bench --suite animation: " + name + ": " + keptAtOnceText(plan) +
                         ": bench fewer configurations (--backends) or a smaller scene");
}

void measureScene(const std::string& path, const BenchCommand& cmd, const std::vector<BenchConfig>& configs,
                  BenchRun& run, std::vector<AnimationScene>& scenes, std::vector<AnimationFrameRow>& rows) {
    const GltfDocument doc = GltfDocument::open(path);
    doc.checkAnimationChoice(cmd.animation.animation);
    AnimationScene info;
    info.path = path;
    const std::string stem = std::filesystem::path(path).stem().string();
    info.name = stem;
    for (int copy = 2; std::any_of(scenes.begin(), scenes.end(), [&](const AnimationScene& s) { return s.name == info.name; });
         ++copy)
        info.name = stem + "_" + std::to_string(copy);
    for (std::size_t a = 0; a < doc.animations().size(); ++a) info.animations.push_back(animationText(doc.animations()[a], a));
    info.animated = !doc.animations().empty();
    if (!info.animated)
        std::cerr << "dacrt bench: " << path << " has no animation: every frame is the same scene, and each still "
                  << "pays its whole work (evaluation, bounds or build or refit, trace) as an animated one would\n";

    GltfSelection selection{.scene = {}, .animation = cmd.animation.animation, .time = 0.0};
    std::vector<std::int64_t> frames;
    for (std::int64_t k = 0; k < cmd.animation.frames.count(); ++k) frames.push_back(cmd.animation.frames.frameAt(k));
    selection.time = timeOfFrame(frames.front(), cmd.animation.fps);
    Scene first = doc.scene(selection);
    // The view is fixed by the first frame (unless the scene's own camera moves): a default
    // view framing each frame's bounds would follow the motion and hide it.
    const Box firstBox = sceneBounds(first.triangles);
    CameraOptions view = cmd.camera;
    view.orbit = 0;
    const double aspect = double(cmd.width) / double(cmd.height);
    std::size_t previousCount = first.triangleCount();
    // The scene every configuration traces, each frame's triangles written into it.
    TraceScene traced = adoptScene(std::move(first), firstBox);

    checkAnimationMemory(configs, traced, makeCameras(sceneOf(traced), firstBox, view, aspect).front(), cmd, info.name, run);
    std::vector<AnimatedConfig> states;
    for (const BenchConfig& config : configs) states.push_back(startAnimatedConfig(config, traced, run));
    Progress progress("dacrt bench", frames.size() * configs.size() * std::size_t(cmd.warmup + cmd.repeat));
    const std::size_t raysPerFrame = std::size_t(cmd.width) * std::size_t(cmd.height);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const std::int64_t f = frames[i];
        selection.time = timeOfFrame(f, cmd.animation.fps);
        progress.stage(info.name + ": frame " + std::to_string(f) + " (" + std::to_string(i + 1) + " of " +
                       std::to_string(frames.size()) + "), " + std::to_string(configs.size()) + " configurations");
        std::vector<FrameRuns> perConfig(configs.size());
        std::vector<double> evaluateMs;
        std::size_t count = 0;
        bool topologyChanged = false;
        for (int w = 0; w < cmd.warmup + cmd.repeat; ++w) {
            const auto start = Clock::now();
            Scene frame = doc.scene(selection);
            const double evaluated = msSince(start);
            if (w == 0) {
                count = frame.triangleCount();
                topologyChanged = i > 0 && count != previousCount;
                if (topologyChanged) {
                    info.topologyChanges.push_back(f);
                    std::cerr << "dacrt bench: " << info.name << ", frame " << f << ": " << count << " triangles, the frame "
                              << "before had " << previousCount << ": a refit cannot follow a change of topology, so the "
                              << "refit peers rebuild their structure for this frame\n";
                }
            } else if (frame.triangleCount() != count) {
                throw InternalError("bench: frame " + std::to_string(f) + " evaluated to " +
                                    std::to_string(frame.triangleCount()) + " triangles, before to " + std::to_string(count));
            }
            const Camera camera = makeCameras(frame, firstBox, view, aspect).front();
            const bool timed = w >= cmd.warmup;
            if (timed) evaluateMs.push_back(evaluated);
            // In place where the count stays, so that the peers update the structure they keep;
            // a new scene where the topology changed (in every repeat of the frame: a refit
            // cannot follow it, so the refit peers build anew, as the frame's one pass would).
            const auto copyStart = Clock::now();
            if (topologyChanged) {
                const Box box = sceneBounds(frame.triangles);
                traced = adoptScene(std::move(frame), box);
            } else {
                replaceScene(traced, std::move(frame));
            }
            const double copyMs = msSince(copyStart);
            const Scene& posed = sceneOf(traced);
            std::vector<Bounds> bounds;  // for the peers' near ties, once per frame
            for (std::size_t c = 0; c < states.size(); ++c) {
                AnimatedConfig& a = states[c];
                progress.step(info.name + " frame " + std::to_string(f) + " " + a.config.series);
                AnimatedWork work =
                    traceAnimatedFrame(a, traced, camera, cmd.width, cmd.height, topologyChanged, copyMs, run);
                settleAfter(a.config.backend());
                if (!timed) continue;
                if (w == cmd.warmup && c > 0) {  // every backend is deterministic: one run's hits stand for all
                    const bool exact = !isPeer(a.config.backend());
                    if (!exact && bounds.empty()) bounds = allTriangleBounds(posed.triangles);
                    // The frame's camera rays, as cpu-seq's (the first configuration's) trace
                    // left them: embree with its rays made in the loop stores none.
                    checkHits(perConfig[0].runs.front().hits, work.hits, exact, posed, bounds, states.front().rays,
                              run.pools.of(a.config.threads()), perConfig[c]);
                }
                perConfig[c].runs.push_back(std::move(work));
            }
            for (FrameRuns& r : perConfig)  // the hits are checked: only the reference's are kept
                for (std::size_t k = (&r == &perConfig[0] ? 1 : 0); k < r.runs.size(); ++k) r.runs[k].hits = {};
        }
        const double evaluate = median(evaluateMs);
        for (std::size_t c = 0; c < states.size(); ++c) {
            const AnimatedWork& m = medianRun(perConfig[c].runs);
            AnimationFrameRow row;
            row.scene = info.name;
            row.frame = f;
            row.timeS = selection.time;
            row.triangles = count;
            row.topologyChanged = topologyChanged;
            row.config = states[c].config;
            row.rays = raysPerFrame;
            row.evaluateMs = evaluate;
            row.prepareMs = m.prepareMs;
            row.buildMs = m.buildMs;
            row.traceMs = m.traceMs;
            row.workMs = m.workMs;
            row.copyMs = m.copyMs;
            row.rebuilt = m.rebuilt;
            row.partsMs = m.parts;
            row.differing = perConfig[c].differing;
            row.nearTies = perConfig[c].nearTies;
            row.realErrors = perConfig[c].realErrors;
            row.exactRequired = !isPeer(row.config.backend());
            row.initialBuildMs = states[c].initialBuildMs;
            rows.push_back(std::move(row));
        }
        previousCount = count;
    }
    scenes.push_back(std::move(info));
}

}  // namespace

int runAnimationSuite(const BenchCommand& cmd, const std::vector<BenchConfig>& configs, BenchRun& run) {
    if (configs.empty() || configs.front().backend() != Backend::CpuSeq)
        throw InternalError("--suite animation needs cpu-seq's default first: every frame is checked against it");
    std::vector<AnimationScene> scenes;
    std::vector<AnimationFrameRow> rows;
    for (const std::string& path : cmd.scenes) measureScene(path, cmd, configs, run, scenes, rows);

    printAnimationTables(cmd, scenes, rows);
    writeAnimationOutputs(cmd, scenes, rows, run.tracer, run.hardwareThreads);
    std::cerr << "dacrt bench: wrote " << cmd.csvPath << " and " << cmd.jsonPath << "\n";
    int code = (reportValidationErrors(run.tracer, std::cerr) ? kExitValidation : kExitSuccess);
    for (const AnimationFrameRow& r : rows) {
        if (!r.exactRequired || r.differing == 0) continue;
        std::cerr << "dacrt bench: error: " << r.scene << ", frame " << r.frame << ", " << r.config.series << ": "
                  << r.differing << " of " << r.rays << " primary hits differ from cpu-seq's (dacrt's backends must "
                  << "match it exactly)\n";
        if (code == kExitSuccess) code = kExitCheckFailed;
    }
    return code;
}

}  // namespace dacrt
