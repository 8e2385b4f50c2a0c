#include "bench/bench_passes.hpp"

#include <algorithm>
#include <bit>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench/bench_configs.hpp"
#include "bench/bench_frame.hpp"
#include "bench/bench_memory.hpp"
#include "bench/bench_report.hpp"
#include "app/exit_codes.hpp"
#include "app/json_keys.hpp"
#include "app/progress.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/lights.hpp"
#include "core/timing.hpp"
#include "library/pass_options.hpp"

namespace dacrt {
namespace {

// What one pass of one frame took and answered.
struct PassFrame {
    double ms = 0.0;
    std::uint64_t rays = 0;
    std::vector<std::pair<std::string, double>> parts;
    std::vector<RayHit> hits;  // per slot (the primary pass: per pixel)
    bool together = false;     // traced with the frame's other passes (PassOutput::tracedIn)
};

// A secondary pass of the frame, as traceFrame traced it: its rays made from the primary hits
// (gpu: on the device, where the primary pass left them; the others on the host, on the
// configuration's threads) and traced for any hit (Embree: rtcOccluded16 on runs of 16 rays,
// over the structure the primary pass left; ray queries: terminate on the first hit).
PassFrame secondaryPassFrame(const BenchConfig& c, PassOutput& pass) {
    PassFrame f;
    // Pipeline compilation within a trace is a cost of the process, not of the pass (render
    // reports it apart too): with --warmup 0 the first frame would otherwise carry it.
    f.ms = pass.ms - pass.output.timings.pipelineCompileMs;
    f.rays = pass.rays;
    addTraceParts(pass.output, f.parts);
    // RayQueryScene::trace builds (dynamic) or refits (refit) its structure in every call: it
    // has no call that traces alone. The frame paid for that once, in its primary pass; the
    // repeat here is taken out of the pass's time by its GPU timestamps (the vertices' upload
    // before it, a copy in host memory on lavapipe, stays in).
    if (c.backend() == Backend::RayQuery)
        for (auto& [name, ms] : f.parts)
            if (name == "build" || name == "refit") {
                f.ms -= ms;
                name = "not counted: " + name + " repeated by the pass";
            }
    f.hits = std::move(pass.output.hits);
    f.together = pass.tracedIn != PassOutput::kTracedAlone;
    return f;
}

// One lit frame of embree with its rays made in the loop (in_loop_embree.hpp): the primary
// pass (the structure, then the camera's rays made and traced), then each secondary pass from
// its hits (the rays made per packet and traced), each timed around its call.
std::vector<PassFrame> traceLitFrameInLoop(const BenchConfig& c, const Camera& camera, const BenchCommand& cmd,
                                           const std::vector<FramePass>& passes, BenchRun& run, InLoopEmbree& embree) {
    ThreadPool& pool = run.pools.of(c.threads());
    std::vector<PassFrame> frame(1 + passes.size());
    // The answers and parts as the Tracer's passes report them, after the pass's time was taken.
    const auto record = [&](PassFrame& f, double ms, const std::vector<Hit>& hits, const PhaseTimes& phases,
                            std::uint64_t rays) {
        f.ms = ms;
        f.rays = rays;
        TraceOutput out = outputOf(hits, phases, pool.size(), ms);
        addTraceParts(out, f.parts);
        f.hits = std::move(out.hits);
    };
    auto start = Clock::now();
    PhaseTimes primary = embree.nextFrame();
    primary.add(embree.tracePrimary(camera, cmd.width, cmd.height, pool));
    record(frame[0], msSince(start), embree.hits(), primary, embree.hits().size());
    for (std::size_t p = 0; p < passes.size(); ++p) {
        start = Clock::now();
        std::uint64_t rays = 0;
        const PhaseTimes phases = embree.occludeSecondary(passes[p], pool, rays);
        record(frame[1 + p], msSince(start), embree.slots(), phases, rays);
    }
    return frame;
}

// One lit frame of a configuration: the camera's rays, then the Tracer's frame (traceFrame):
// the primary pass, then each secondary pass from its hits, back to back as render runs them.
std::vector<PassFrame> traceLitFrame(const BenchConfig& c, const BenchScene& s, const Camera& camera,
                                     const BenchCommand& cmd, const std::vector<FramePass>& passes, BenchRun& run,
                                     std::vector<Ray>& rayBuffer, InLoopEmbree& embree) {
    if (c.raysInLoop) return traceLitFrameInLoop(c, camera, cmd, passes, run, embree);
    useConfig(run.tracer, c);
    const auto start = Clock::now();
    RayBatch rays = makeCameraRays(camera, cmd.width, cmd.height, run.pools.of(c.threads()), rayBuffer);
    const double raysMs = msSince(start);
    FrameOutput out = run.tracer.traceFrame(s.traced, rays, passes);
    if (out.passes.size() != passes.size()) throw InternalError("bench: a frame traced fewer passes than asked");
    std::vector<PassFrame> frame(1 + passes.size());
    TraceOutput& primary = out.primary;
    frame[0].ms = raysMs + primary.timings.totalMs - primary.timings.pipelineCompileMs;
    frame[0].rays = rays.size();
    frame[0].parts = {{"rays", raysMs}, {"tracer", primary.timings.totalMs}};
    addTraceParts(primary, frame[0].parts);
    frame[0].hits = std::move(primary.hits);
    for (std::size_t p = 0; p < passes.size(); ++p) frame[1 + p] = secondaryPassFrame(c, out.passes[p]);
    rayBuffer = releaseRays(std::move(rays));
    return frame;
}

// A slot's visibility, all that an any-hit answer promises: no ray made, open, or blocked.
int visibilityOf(const RayHit& h) { return h.primitive == kNotTracedPrimitive ? 0 : h.primitive == kNoPrimitive ? 1 : 2; }

std::uint64_t mismatches(const std::vector<RayHit>& reference, const std::vector<RayHit>& got, bool primary,
                         bool exactDepth) {
    if (reference.size() != got.size())
        throw InternalError("a pass answered " + std::to_string(got.size()) + " slots, cpu-seq " +
                            std::to_string(reference.size()));
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
        if (primary)
            n += reference[i].primitive != got[i].primitive ||
                 (exactDepth && std::bit_cast<std::uint32_t>(reference[i].t) != std::bit_cast<std::uint32_t>(got[i].t));
        else
            n += visibilityOf(reference[i]) != visibilityOf(got[i]);
    }
    return n;
}

// One pass's running totals for a configuration over the cameras of a scene.
struct PassTotals {
    std::vector<double> cameraMs;
    double minSum = 0.0, medianSum = 0.0, meanMs = 0.0, raysSum = 0.0, slotsSum = 0.0;
    std::map<std::string, double> partSums;
    std::vector<std::string> partOrder;
    std::uint64_t checked = 0, mismatches = 0;
    std::uint64_t framesTogether = 0;  // timed frames whose passes were traced together

    void addFrame(double ms, const std::vector<std::pair<std::string, double>>& parts, double frames,
                  bool together = false) {
        framesTogether += together;
        cameraMs.push_back(ms);
        meanMs += ms / frames;
        for (const auto& [name, t] : parts) {
            if (!partSums.count(name)) partOrder.push_back(name);
            partSums[name] += t / frames;
        }
    }
    void endCamera() {
        minSum += *std::min_element(cameraMs.begin(), cameraMs.end());
        medianSum += median(cameraMs);
        cameraMs.clear();
    }
};

// A configuration over one scene: its rays' memory, and per pass (primary, each secondary
// pass, then the whole frame) its totals.
struct ConfigRun {
    BenchConfig config;
    std::vector<Ray> rays;
    InLoopEmbree embree;  // embree with its rays made in the loop: its structure and frame buffers
    std::vector<PassTotals> totals;
};

struct SceneRun {
    const BenchScene& s;
    std::vector<FramePass> passes;
    std::vector<ConfigRun> runs;
    std::optional<KeptStates> states;  // bench_memory.hpp: every configuration's, or one at a time
};

// Configurations interleave within every repeat (as bench.cpp's), unless their kept state
// must be held one at a time.
void measureCamera(SceneRun& run, std::size_t k, const BenchCommand& cmd, BenchRun& bench, Progress& progress) {
    const BenchScene& s = run.s;
    progress.stage(s.name + ": camera " + std::to_string(k + 1) + " of " + std::to_string(s.cameras.size()) + ", " +
                   std::to_string(run.runs.size()) + " configurations, " + std::to_string(1 + run.passes.size()) +
                   " passes each");
    const double frames = double(s.cameras.size() * std::size_t(cmd.repeat));
    const std::size_t passCount = 1 + run.passes.size();
    std::vector<std::vector<RayHit>> reference;  // cpu-seq's answers, the first configuration's
    for (const auto& [w, c] : frameOrder(cmd.warmup + cmd.repeat, run.runs.size(), run.states->oneAtATime())) {
        ConfigRun& r = run.runs[c];
        progress.step(s.name + " " + configLabel(r.config) + " camera " + std::to_string(k));
        run.states->hold(c, r.config, s.traced, bench);
        std::vector<PassFrame> frame = traceLitFrame(r.config, s, s.cameras[k], cmd, run.passes, bench, r.rays, r.embree);
        settleAfter(r.config.backend());
        if (w < cmd.warmup) continue;
        double frameMs = 0.0;
        for (std::size_t p = 0; p < passCount; ++p) {
            r.totals[p].addFrame(frame[p].ms, frame[p].parts, frames, frame[p].together);
            frameMs += frame[p].ms;
        }
        std::vector<std::pair<std::string, double>> perPass;
        for (std::size_t p = 0; p < passCount; ++p)
            perPass.emplace_back(p == 0 ? std::string("primary") : run.passes[p - 1].name, frame[p].ms);
        r.totals[passCount].addFrame(frameMs, perPass, frames);
        if (w != cmd.warmup) continue;  // every backend is deterministic: one frame's answers stand for all
        if (c == 0)
            for (const PassFrame& f : frame) reference.push_back(f.hits);
        const bool exact = !isPeer(r.config.backend());
        PassTotals& whole = r.totals[passCount];
        for (std::size_t p = 0; p < passCount; ++p) {
            const std::uint64_t differ = mismatches(reference[p], frame[p].hits, p == 0, exact);
            for (PassTotals* t : {&r.totals[p], &whole}) {
                t->raysSum += double(frame[p].rays);
                t->slotsSum += double(frame[p].hits.size());
                t->checked += frame[p].hits.size();
                t->mismatches += differ;
            }
        }
    }
    for (ConfigRun& r : run.runs)
        for (PassTotals& t : r.totals) t.endCamera();
}

void measureScene(const std::string& path, const BenchCommand& cmd, const std::vector<BenchConfig>& configs,
                  BenchRun& bench, std::vector<std::string>& taken, std::vector<PassRow>& rows) {
    const BenchScene s = loadBenchScene(path, cmd, taken);
    taken.push_back(s.name);
    // The lights are fixed in the world, placed (a default key light) from the orbit's first
    // camera, as render places them.
    bool headlight = false;
    const std::vector<Light> lights = frameLights(s.scene(), s.cameras.front(), s.box, cmd.passes.lights, headlight);
    SceneRun run{s, framePasses(lights, cmd.passes, s.box, 0), {}, {}};
    for (const BenchConfig& config : configs) {
        ConfigRun r;
        r.config = config;
        r.totals.resize(run.passes.size() + 2);
        run.runs.push_back(std::move(r));
    }
    std::vector<InLoopEmbree*> embree;
    for (ConfigRun& r : run.runs) embree.push_back(&r.embree);
    run.states.emplace(planSceneMemory(configs, s, cmd, bench).oneAtATime, embree);
    run.states->prepareAll(configs, s.traced, bench);
    Progress progress("dacrt bench", s.cameras.size() * configs.size() * std::size_t(cmd.warmup + cmd.repeat));
    for (std::size_t k = 0; k < s.cameras.size(); ++k) measureCamera(run, k, cmd, bench, progress);

    const double cameras = double(s.cameras.size());
    const std::size_t passCount = 1 + run.passes.size();
    for (ConfigRun& r : run.runs) {
        for (std::size_t p = 0; p <= passCount; ++p) {
            const PassTotals& t = r.totals[p];
            PassRow row;
            row.scene = s.name;
            row.triangles = s.scene().triangleCount();
            row.pixels = std::size_t(cmd.width) * std::size_t(cmd.height);
            row.cameras = int(s.cameras.size());
            row.config = r.config;
            row.passIndex = int(p);
            if (p == 0) {
                row.pass = row.kind = "primary";
            } else if (p == passCount) {
                row.pass = row.kind = "frame";
            } else {
                const FramePass& pass = run.passes[p - 1];
                row.pass = pass.name;
                row.kind = pass.kind == PassKind::Shadow ? "shadow" : "occlusion";
                row.raysPerHit = pass.raysPerHit;
            }
            row.slotsPerFrame = t.slotsSum / cameras;
            row.raysPerFrame = t.raysSum / cameras;
            row.msMin = t.minSum / cameras;
            row.msMedian = t.medianSum / cameras;
            row.msMean = t.meanMs;
            for (const std::string& name : t.partOrder) row.partsMs.emplace_back(name, t.partSums.at(name));
            row.checkedSlots = t.checked;
            row.mismatches = t.mismatches;
            row.exactRequired = !isPeer(r.config.backend());
            row.framesTogether = t.framesTogether;
            rows.push_back(std::move(row));
        }
    }
}

// A peer's per-frame build or refit: in its primary pass, and apart here as the peers suite
// reports it.
std::optional<double> buildMsOf(const PassRow& r) {
    if (r.kind != "primary") return std::nullopt;
    for (const auto& [name, ms] : r.partsMs)
        if (name == "build" || name == "refit") return ms;
    return std::nullopt;
}

nlohmann::ordered_json passRowJson(const PassRow& r) {
    nlohmann::ordered_json j;
    j["scene"] = r.scene;
    j["triangles"] = r.triangles;
    j["pixels_per_frame"] = r.pixels;
    j["cameras"] = r.cameras;
    recordConfig(j, r.config);
    j["pass_index"] = r.passIndex;
    j["pass"] = r.pass;
    j["pass_kind"] = r.kind;
    j["rays_per_hit"] = r.raysPerHit;
    j["slots_per_frame"] = r.slotsPerFrame;
    j["rays_per_frame"] = r.raysPerFrame;
    j["ms_min"] = r.msMin;
    j["ms_median"] = r.msMedian;
    j["ms_mean"] = r.msMean;
    // Passes traced together (--pass-tracing): the trace's time is the last pass's, a pass
    // before it reads 0 ms in those frames.
    if (r.kind == "shadow" || r.kind == "occlusion") j["frames_traced_together"] = r.framesTogether;
    j["mrays_per_s"] = r.msMedian > 0.0 ? r.raysPerFrame / (r.msMedian * 1e3) : 0.0;
    const std::optional<double> build = buildMsOf(r);
    j["build_ms"] = build ? nlohmann::ordered_json(*build) : nullptr;
    nlohmann::ordered_json parts = nlohmann::ordered_json::object();
    for (const auto& [name, ms] : r.partsMs) parts[jsonKey(name)] = ms;
    j["parts_ms"] = parts;
    j["checked_slots"] = r.checkedSlots;
    j["visibility_mismatches"] = r.mismatches;
    j["mismatch_fraction"] = r.checkedSlots ? double(r.mismatches) / double(r.checkedSlots) : 0.0;
    j["exact_required"] = r.exactRequired;
    return j;
}

void printPassSummary(const std::vector<PassRow>& rows) {
    std::cout << std::left << std::setw(30) << "series" << std::setw(28) << "pass" << std::right << std::setw(12)
              << "rays" << std::setw(10) << "min ms" << std::setw(10) << "median" << std::setw(9) << "Mray/s"
              << std::setw(10) << "build ms" << std::setw(12) << "mismatches" << "\n";
    std::string scene;
    for (const PassRow& r : rows) {
        if (r.scene != scene) {
            scene = r.scene;
            std::cout << "== " << scene << " (" << r.triangles << " triangles, " << r.cameras << " cameras, "
                      << r.pixels << " pixels)\n";
        }
        const std::optional<double> build = buildMsOf(r);
        std::ostringstream b;
        if (build) b << std::fixed << std::setprecision(1) << *build;
        std::cout << std::left << std::setw(30) << configLabel(r.config) << std::setw(28) << r.pass << std::right
                  << std::fixed << std::setprecision(0) << std::setw(12) << r.raysPerFrame << std::setprecision(1)
                  << std::setw(10) << r.msMin << std::setw(10) << r.msMedian << std::setprecision(2) << std::setw(9)
                  << (r.msMedian > 0.0 ? r.raysPerFrame / (r.msMedian * 1e3) : 0.0) << std::setw(10) << b.str()
                  << std::setw(12) << r.mismatches << (r.exactRequired && r.mismatches ? "  MUST BE 0" : "") << "\n";
    }
    std::cout << "(rays: made per frame; mismatches: slots whose answer differs from cpu-seq's, summed over the "
                 "cameras; build: a peer's per-frame build or refit, within its primary pass)\n";
}

void writePassOutputs(const BenchCommand& cmd, const std::vector<PassRow>& rows, const BenchRun& run) {
    std::vector<nlohmann::ordered_json> json;
    for (const PassRow& r : rows) json.push_back(passRowJson(r));
    writeCsvOf(cmd.csvPath,
               {"scene", "triangles", "pixels_per_frame", "cameras", "backend", "series", "config", "default", "options",
                "threads", "pass_index", "pass", "pass_kind", "rays_per_hit", "slots_per_frame", "rays_per_frame",
                "ms_min", "ms_median", "ms_mean", "mrays_per_s", "build_ms", "checked_slots", "visibility_mismatches",
                "mismatch_fraction", "exact_required"},
               json);
    nlohmann::ordered_json j = runJson(cmd, run.tracer, run.hardwareThreads);
    j["rows"] = nlohmann::ordered_json::array();
    for (nlohmann::ordered_json& row : json) j["rows"].push_back(std::move(row));
    writeFileAtomically(cmd.jsonPath, j.dump(2) + "\n");
}

}  // namespace

int runPassesSuite(const BenchCommand& cmd, const std::vector<BenchConfig>& configs, BenchRun& run) {
    if (configs.empty() || configs.front().backend() != Backend::CpuSeq)
        throw InternalError("--suite passes needs cpu-seq's default first: every pass is checked against it");
    std::vector<PassRow> rows;
    std::vector<std::string> taken;
    for (const std::string& path : cmd.scenes) measureScene(path, cmd, configs, run, taken, rows);

    printPassSummary(rows);
    writePassOutputs(cmd, rows, run);
    std::cerr << "dacrt bench: wrote " << cmd.csvPath << " and " << cmd.jsonPath
              << " (tables: python3 tools/bench/tables.py passes " << cmd.jsonPath << " SCENE)\n";
    int code = (reportValidationErrors(run.tracer, std::cerr) ? kExitValidation : kExitSuccess);
    for (const PassRow& r : rows) {
        if (!r.exactRequired || r.mismatches == 0 || r.kind == "frame") continue;
        std::cerr << "dacrt bench: error: " << r.scene << ", " << configLabel(r.config) << ", " << r.pass << ": "
                  << r.mismatches << " of " << r.checkedSlots << " slots differ from cpu-seq's (dacrt's backends must "
                  << "match it exactly)\n";
        if (code == kExitSuccess) code = kExitCheckFailed;
    }
    return code;
}

}  // namespace dacrt
