#include "bench/bench.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include <dacrt/devices.hpp>

#include "bench/bench_animation.hpp"
#include "bench/bench_configs.hpp"
#include "bench/bench_frame.hpp"
#include "bench/bench_memory.hpp"
#include "bench/bench_passes.hpp"
#include "bench/bench_report.hpp"
#include "bench/reference_cache.hpp"
#include "app/output_paths.hpp"
#include "app/exit_codes.hpp"
#include "app/progress.hpp"
#include "core/atomic_file.hpp"
#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/shading.hpp"
#include "core/timing.hpp"
#include "oracle/compare.hpp"

namespace dacrt {
namespace {

// ---- before anything runs ---------------------------------------------------------------

void checkBenchCommand(const BenchCommand& cmd) {
    if (cmd.scenes.empty()) throw InputError("bench: name at least one scene");
    if (cmd.orbit < 1 || cmd.repeat < 1 || cmd.warmup < 0)
        throw InputError("bench: --orbit and --repeat must be >= 1, --warmup >= 0");
    if (cmd.width < 1 || cmd.height < 1 || cmd.width > 16384 || cmd.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
    if (cmd.suite == BenchSuite::Passes) checkPassOptions(cmd.passes);
    if (cmd.suite == BenchSuite::Animation) {
        if (!(std::isfinite(cmd.animation.fps) && cmd.animation.fps > 0.0))
            throw InputError("--fps: frames per second must be a finite number above 0");
        parseFrameRange(cmd.animation.frames.text());  // the range's own checks, for a command made in code
        if (cmd.orbit != 1)
            throw InputError("bench: --suite animation traces each frame from one camera (the scene's, which may move, "
                             "or --eye/--target); --orbit is for the still suites");
    }
}

// Resolves the output paths and checks that they can be written before anything is timed:
// a long run must not fail at its end. Only the --out folder itself may be created (for the
// outputs it holds), never a folder above it or one the user did not name.
BenchCommand withOutputs(BenchCommand cmd) {
    const bool outHoldsAny = cmd.csvPath.empty() || cmd.jsonPath.empty();
    if (cmd.csvPath.empty()) cmd.csvPath = (std::filesystem::path(cmd.outDir) / "bench.csv").string();
    if (cmd.jsonPath.empty()) cmd.jsonPath = (std::filesystem::path(cmd.outDir) / "bench.json").string();
    std::error_code ec;
    if (outHoldsAny && !std::filesystem::is_directory(cmd.outDir, ec)) {
        const std::filesystem::path parent = std::filesystem::path(cmd.outDir).parent_path();
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
            throw InputError("--out " + cmd.outDir + ": the folder " + parent.string() + " does not exist");
        if (!std::filesystem::create_directory(cmd.outDir, ec) && ec)
            throw InputError("--out " + cmd.outDir + ": cannot create the folder (" + ec.message() + ")");
    }
    checkOutputs({{"--csv", cmd.csvPath, OutputFormat::Text}, {"--json", cmd.jsonPath, OutputFormat::Text}}, cmd.scenes);
    return cmd;
}

// --suite passes checks every pass, --suite animation every frame, against cpu-seq's, so
// cpu-seq runs first, named or not.
std::vector<Backend> withReferenceFirst(const BenchCommand& cmd, std::vector<Backend> backends) {
    const bool checked = cmd.suite == BenchSuite::Passes || cmd.suite == BenchSuite::Animation;
    if (!checked || (!backends.empty() && backends.front() == Backend::CpuSeq)) return backends;
    const auto named = std::find(backends.begin(), backends.end(), Backend::CpuSeq);
    if (named != backends.end()) backends.erase(named);
    else
        std::cerr << "dacrt bench: --suite " << toString(cmd.suite) << " checks every "
                  << (cmd.suite == BenchSuite::Passes ? "pass" : "frame") << " against cpu-seq's, so cpu-seq runs too\n";
    backends.insert(backends.begin(), Backend::CpuSeq);
    return backends;
}

// The backends named, or the defaults: cpu-seq, cpu, gpu where a Vulkan device exists, embree
// (rayquery joins them once the device is open: addRayQuery).
std::vector<Backend> chooseBackends(const BenchCommand& cmd) {
    if (!cmd.backends.empty()) return withReferenceFirst(cmd, cmd.backends);
    std::vector<Backend> backends = {Backend::CpuSeq, Backend::Cpu};
    if (!listDevices().vulkan.empty())
        backends.push_back(Backend::Gpu);
    else
        std::cerr << "dacrt bench: no Vulkan device, so no gpu rows (name --backends gpu to make that an error)\n";
    if (cmd.suite != BenchSuite::Table51) backends.push_back(Backend::Embree);
    return backends;
}

// The run's one Tracer: on the Vulkan device (--device, --validate) where a backend of the run
// runs there, so that a missing or unmatched device fails before any long work; else on the CPU
// alone (the device options then choose nothing, as before the Tracer).
Tracer openTracer(const BenchCommand& cmd, const std::vector<Backend>& backends) {
    TracerOptions o;
    // gpu where it is listed, so that gpuDefaults answers under the bench's profile.
    auto vulkan = std::find(backends.begin(), backends.end(), Backend::Gpu);
    if (vulkan == backends.end()) vulkan = std::find_if(backends.begin(), backends.end(), runsOnVulkan);
    if (vulkan == backends.end()) return Tracer(o);
    o.trace.backend = *vulkan;
    o.device = cmd.device;
    o.validate = cmd.validate;
    if (o.trace.backend == Backend::Gpu) o.gpu.profile = cmd.gpuProfile;  // gpuDefaults: the sweep's, under it
    return Tracer(o);
}

// The default backends' peer on the device gpu opened, where that device has ray query.
void addRayQuery(const BenchCommand& cmd, const Tracer& tracer, std::vector<Backend>& backends) {
    if (!cmd.backends.empty() || cmd.suite == BenchSuite::Table51) return;
    const std::optional<VulkanDeviceProperties> device = tracer.deviceProperties();
    if (device && device->rayQuery) backends.push_back(Backend::RayQuery);
    else if (device)
        std::cerr << "dacrt bench: the Vulkan device has no ray query, so no rayquery rows (Mesa >= 24.1 has it)\n";
}

std::vector<BenchConfig> chooseConfigs(const BenchCommand& cmd, const std::vector<Backend>& backends,
                                       const Tracer& tracer, unsigned hardwareThreads) {
    const Tracer::GpuDefaults gpu = tracer.gpuDefaults().value_or(Tracer::GpuDefaults{16, 1, 0});
    std::vector<BenchConfig> configs;
    for (Backend b : backends) {
        const std::vector<BenchConfig> more =
            cmd.suite == BenchSuite::Sweep    ? sweepConfigs(b, hardwareThreads, gpu.regions, gpu.rayGroups, gpu.leafBalance)
            : cmd.suite == BenchSuite::Peers  ? peerConfigs(b, hardwareThreads)
            : cmd.suite == BenchSuite::Skips  ? skipConfigs(b, hardwareThreads)
            : cmd.suite == BenchSuite::Passes ? passesConfigs(b, hardwareThreads)
            : cmd.suite == BenchSuite::Animation ? animationConfigs(b, hardwareThreads)
                                              : table51Configs(b, hardwareThreads);
        configs.insert(configs.end(), more.begin(), more.end());
    }
    for (BenchConfig& c : configs)
        if (c.backend() == Backend::Gpu) c.options.gpu.profile = cmd.gpuProfile;
    return configs;
}

// ---- one scene --------------------------------------------------------------------------

// A configuration's running totals over the cameras of one scene.
struct Accumulator {
    BenchRow row;
    double minSum = 0.0, medianSum = 0.0;
    std::map<std::string, double> partSums;
    std::vector<std::string> partOrder;
    std::vector<double> cameraMs;
    std::vector<Ray> rays;  // the camera rays' memory, kept from frame to frame
    InLoopEmbree embree;    // embree with its rays made in the loop: its structure and frame buffer
};

// The rows of the scene.
std::vector<Accumulator> startRows(const BenchScene& s, const BenchCommand& cmd, const std::vector<BenchConfig>& configs) {
    std::vector<Accumulator> acc(configs.size());
    for (std::size_t c = 0; c < configs.size(); ++c) {
        BenchRow& row = acc[c].row;
        row.scene = s.name;
        row.triangles = s.scene().triangleCount();
        row.raysPerFrame = std::size_t(cmd.width) * std::size_t(cmd.height);
        row.cameras = int(s.cameras.size());
        row.config = configs[c];
    }
    return acc;
}

// Every configuration's frames of one camera. Configurations are interleaved (repeat, then
// configuration), so that a slow spell of this shared machine lands on every configuration
// alike instead of on whichever one happened to run then, unless their kept state must be held
// one at a time (bench_memory.hpp).
void measureCamera(const BenchScene& s, std::size_t k, const BenchCommand& cmd, const std::string& cacheDir,
                   std::vector<Accumulator>& acc, KeptStates& states, BenchRun& run, Progress& progress) {
    progress.stage(s.name + ": camera " + std::to_string(k + 1) + " of " + std::to_string(s.cameras.size()) + ", " +
                   std::to_string(acc.size()) + " configurations");
    progress.step(s.name + " float64 reference, camera " + std::to_string(k));
    const Camera& camera = s.cameras[k];
    const std::vector<Ray> rays = primaryRays(camera, cmd.width, cmd.height);
    ThreadPool& pool = run.pools.of(run.hardwareThreads);
    const Scene& scene = s.scene();
    const std::vector<ReferenceHit> reference =
        cachedReference(scene, rays, referenceKey(s.trianglesDigest, rays, camera, cmd.width, cmd.height),
                        cmd.useCache ? cacheDir : std::string(), pool);
    std::vector<Hit> asHits(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) asHits[i] = Hit{float(reference[i].t), reference[i].prim, 0.0f, 0.0f};
    const std::vector<std::uint8_t> referenceShaded = shadeImage(scene, HitImage{cmd.width, cmd.height, &rays, &asHits});
    const std::size_t frames = s.cameras.size() * std::size_t(cmd.repeat);
    for (const auto& [w, c] : frameOrder(cmd.warmup + cmd.repeat, acc.size(), states.oneAtATime())) {
        Accumulator& a = acc[c];
        const BenchConfig& config = a.row.config;
        progress.step(s.name + " " + config.series + " " + config.name + " camera " + std::to_string(k));
        states.hold(c, config, s.traced, run);
        const FrameOutcome frame = traceStillFrame(config, s.traced, camera, cmd.width, cmd.height, run, a.rays, a.embree);
        settleAfter(config.backend());
        if (w < cmd.warmup) continue;
        a.cameraMs.push_back(frame.ms);
        for (const auto& [name, ms] : frame.parts) {
            if (!a.partSums.count(name)) a.partOrder.push_back(name);
            a.partSums[name] += ms / double(frames);
        }
        if (w != cmd.warmup) continue;  // every backend is deterministic: one frame's hits stand for all
        const std::vector<Hit> hits = hitsOf(frame.output.hits);
        const std::vector<std::uint8_t> shaded = shadeImage(scene, HitImage{cmd.width, cmd.height, &rays, &hits});
        a.row.errors.add(measureErrors(scene.triangles, s.bounds, rays, reference, hits, referenceShaded, shaded, pool));
        a.row.regions = frame.output.counters.regions;
        a.row.divisionAxis = frame.output.counters.divisionAxis;
    }
    for (Accumulator& a : acc) {
        // Per camera over the repeats, then the mean over the orbit: each camera is its own
        // workload, so its own minimum is the least noisy figure for it.
        a.minSum += *std::min_element(a.cameraMs.begin(), a.cameraMs.end());
        a.medianSum += median(a.cameraMs);
        a.cameraMs.clear();
    }
}

void finishRows(std::vector<Accumulator>& acc, std::size_t cameras, std::vector<BenchRow>& rows) {
    for (Accumulator& a : acc) {
        for (const std::string& name : a.partOrder) a.row.partsMs.emplace_back(name, a.partSums[name]);
        a.row.frameMsMin = a.minSum / double(cameras);
        a.row.frameMsMedian = a.medianSum / double(cameras);
        rows.push_back(std::move(a.row));
    }
}

void measureScene(const std::string& path, const BenchCommand& cmd, const std::vector<BenchConfig>& configs,
                  BenchRun& run, std::vector<BenchRow>& rows) {
    std::vector<std::string> taken;
    for (const BenchRow& r : rows) taken.push_back(r.scene);
    const BenchScene s = loadBenchScene(path, cmd, taken);
    std::vector<Accumulator> acc = startRows(s, cmd, configs);
    std::vector<InLoopEmbree*> embree;
    for (Accumulator& a : acc) embree.push_back(&a.embree);
    KeptStates states(planSceneMemory(configs, s, cmd, run).oneAtATime, embree);
    states.prepareAll(configs, s.traced, run);
    Progress progress("dacrt bench", s.cameras.size() * (1 + configs.size() * std::size_t(cmd.warmup + cmd.repeat)));
    const std::string cacheDir = cmd.cacheDir.empty() ? defaultCacheDir() : cmd.cacheDir;
    for (std::size_t k = 0; k < s.cameras.size(); ++k) measureCamera(s, k, cmd, cacheDir, acc, states, run, progress);
    finishRows(acc, s.cameras.size(), rows);
}

// ---- reports ----------------------------------------------------------------------------

void compareRows(std::vector<BenchRow>& rows) {
    for (BenchRow& r : rows)
        for (const BenchRow& s : rows)
            if (s.scene == r.scene && s.config.backend() == Backend::CpuSeq && s.config.isDefault)
                r.speedupOverSequential = s.frameMsMedian / r.frameMsMedian;
    markPareto(rows);
}

void writeJson(const BenchCommand& cmd, const std::vector<BenchRow>& rows, const BenchRun& run) {
    nlohmann::ordered_json j = runJson(cmd, run.tracer, run.hardwareThreads);
    j["near_tie_tolerance_relative"] = kNearTieRelativeDepth;
    j["pareto_time_margin"] = kParetoTimeMargin;
    j["rows"] = nlohmann::ordered_json::array();
    for (const BenchRow& r : rows) j["rows"].push_back(rowJson(r));
    writeFileAtomically(cmd.jsonPath, j.dump(2) + "\n");
}

}  // namespace

int runBenchCommand(const BenchCommand& request) {
    const BenchCommand cmd = withOutputs(request);
    checkBenchCommand(cmd);
    std::vector<Backend> backends = chooseBackends(cmd);
    BenchRun run{openTracer(cmd, backends), {}, std::max(1u, std::thread::hardware_concurrency())};
    addRayQuery(cmd, run.tracer, backends);
    const std::vector<BenchConfig> configs = chooseConfigs(cmd, backends, run.tracer, run.hardwareThreads);
    if (cmd.suite == BenchSuite::Passes) return runPassesSuite(cmd, configs, run);
    if (cmd.suite == BenchSuite::Animation) return runAnimationSuite(cmd, configs, run);

    std::vector<BenchRow> rows;
    for (const std::string& path : cmd.scenes) measureScene(path, cmd, configs, run, rows);
    compareRows(rows);

    printSummary(rows);
    writeCsv(cmd.csvPath, rows);
    writeJson(cmd, rows, run);
    std::cerr << "dacrt bench: wrote " << cmd.csvPath << " and " << cmd.jsonPath
              << " (plot: python3 tools/bench/plot.py " << cmd.jsonPath << ")\n";
    return reportValidationErrors(run.tracer, std::cerr) ? kExitValidation : kExitSuccess;
}

}  // namespace dacrt
