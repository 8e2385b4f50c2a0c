#include "cmd/bench/bench.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <chrono>
#include <thread>

#include <nlohmann/json.hpp>

#include "cmd/bench/bench_configs.hpp"
#include "cmd/bench/bench_report.hpp"
#include "cmd/bench/reference_cache.hpp"
#include "cmd/output_paths.hpp"
#include "cmd/progress.hpp"
#include "core/atomic_file.hpp"
#include "core/camera.hpp"
#include "core/cpu_model.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/shading.hpp"
#include "core/timing.hpp"
#include "dacrt/simd_kernels.hpp"
#include "oracle/compare.hpp"
#include "gpu/device_defaults.hpp"
#include "oracle/embree_tracer.hpp"

namespace dacrt {
namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// ---- before anything runs ---------------------------------------------------------------

void checkBenchCommand(const BenchCommand& cmd) {
    if (cmd.scenes.empty()) throw InputError("bench: name at least one scene");
    if (cmd.orbit < 1 || cmd.repeat < 1 || cmd.warmup < 0)
        throw InputError("bench: --orbit and --repeat must be >= 1, --warmup >= 0");
    if (cmd.width < 1 || cmd.height < 1 || cmd.width > 16384 || cmd.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
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

std::vector<Backend> chooseBackends(const BenchCommand& cmd) {
    if (!cmd.backends.empty()) return cmd.backends;
    std::vector<Backend> backends = {Backend::CpuSeq, Backend::Cpu};
    const std::vector<gpu::DeviceInfo> devices = gpu::listDevices();
    if (!devices.empty())
        backends.push_back(Backend::Gpu);
    else
        std::cerr << "dacrt bench: no Vulkan device, so no gpu rows (name --backends gpu to make that an error)\n";
    if (cmd.suite != BenchSuite::Table51) {
        backends.push_back(Backend::Embree);
        // The peer on the same device as gpu (the one the dispatcher opens), where that device
        // has ray query; a --device that matches nothing fails when the dispatcher opens it.
        bool rayQuery = false;
        if (!devices.empty()) {
            try {
                rayQuery = devices[gpu::chooseDevice(devices, cmd.devices.device)].rayQuery;
            } catch (const InputError&) {
            }
        }
        if (rayQuery) backends.push_back(Backend::RayQuery);
        else if (!devices.empty())
            std::cerr << "dacrt bench: the Vulkan device has no ray query, so no rayquery rows (Mesa >= 24.1 has it)\n";
    }
    return backends;
}

std::vector<BenchConfig> chooseConfigs(const BenchCommand& cmd, const std::vector<Backend>& backends,
                                       const BackendDispatcher& dispatcher, unsigned hardwareThreads) {
    unsigned gpuDefaultRegions = 16;
    std::uint32_t gpuDefaultRayGroups = 1;
    if (const gpu::Context* context = dispatcher.gpuContext()) {
        gpuDefaultRegions = gpu::defaultGpuRegions(context->info());
        gpuDefaultRayGroups = gpu::defaultRayGroups(context->info(), gpuDefaultRegions);
    }
    std::vector<BenchConfig> configs;
    for (Backend b : backends) {
        const std::vector<BenchConfig> more =
            cmd.suite == BenchSuite::Sweep   ? sweepConfigs(b, hardwareThreads, gpuDefaultRegions, gpuDefaultRayGroups)
            : cmd.suite == BenchSuite::Peers ? peerConfigs(b, hardwareThreads)
            : cmd.suite == BenchSuite::Skips ? skipConfigs(b, hardwareThreads)
                                             : table51Configs(b, hardwareThreads);
        configs.insert(configs.end(), more.begin(), more.end());
    }
    return configs;
}

// ---- one frame --------------------------------------------------------------------------

struct FrameOutcome {
    double ms = 0.0;
    std::vector<std::pair<std::string, double>> parts;
    TraceResult result;
};

// A whole frame as a user pays for it: rays (and, for dacrt's backends, triangle bounds), then the
// backend. Embree's scenes persist across frames as its users keep them: a dynamic one is
// rebuilt each frame (vertex buffer updated, committed: a full LOW-quality build into the
// memory of the last one), a refitted one refitted, a static one left alone.
// The frame's rays and bounds live in buffers kept from frame to frame, as a renderer of a
// dynamic scene keeps them, and are computed on the configuration's threads.
struct FrameBuffers {
    std::vector<Ray> rays;
    std::vector<Bounds> bounds;
};

FrameOutcome traceFrame(const BenchConfig& c, const Scene& scene, const Camera& camera, int width, int height,
                        BackendDispatcher& dispatcher, EmbreeScene* persistentEmbree, RayQueryScene* persistentRayQuery,
                        FrameBuffers& buffers) {
    FrameOutcome out;
    const auto start = Clock::now();
    ThreadPool& pool = dispatcher.pool(c.threads());
    std::vector<Ray>& rays = buffers.rays;
    primaryRays(camera, width, height, pool, rays);
    const bool peer = isPeer(c.backend());
    // Only dacrt's backends read the frame geometry (bounds, scene box, the scan for a shared
    // ray start): the peers' frames do not pay for it.
    FrameGeometry g;
    if (!peer) {
        Box box;
        triangleBoundsInParallel(scene.triangles, pool, buffers.bounds, box);
        g = frameGeometry(scene.triangles, buffers.bounds, rays, box, std::uint32_t(width));
        g.frustum = viewFrustum(camera, width, height);
        g.trianglesVersion = scene.trianglesVersion;  // an orbit: the triangles stay as they are
    }
    const double prepareMs = msSince(start);
    const auto traceStart = Clock::now();
    if (persistentRayQuery) {
        out.result = persistentRayQuery->trace(rays);
    } else if (persistentEmbree) {
        const EmbreeBuild build = c.request.embree.build;
        const double updateMs = build == EmbreeBuild::Static ? 0.0 : persistentEmbree->update();
        out.result = persistentEmbree->trace(rays, dispatcher.pool(c.threads()));
        if (build != EmbreeBuild::Static)
            out.result.phaseMs.insert(out.result.phaseMs.begin(), {build == EmbreeBuild::Refit ? "refit" : "build", updateMs});
    } else {
        out.result = dispatcher.trace(g, c.request);
    }
    out.ms = msSince(start);
    out.parts.emplace_back(peer ? "rays" : "rays and bounds", prepareMs);
    out.parts.emplace_back("tracer", msSince(traceStart));
    for (const auto& p : out.result.phaseMs) out.parts.push_back(p);
    if (out.result.gpu) {
        double gpuMs = 0.0;
        for (const auto& [name, ms] : out.result.gpu->dispatchMs) gpuMs += ms;
        out.parts.emplace_back("gpu timestamps", gpuMs);
    }
    return out;
}

// ---- one scene --------------------------------------------------------------------------

// A configuration's running totals over the cameras of one scene.
struct Accumulator {
    BenchRow row;
    double minSum = 0.0, medianSum = 0.0;
    std::map<std::string, double> partSums;
    std::vector<std::string> partOrder;
    std::unique_ptr<EmbreeScene> persistentEmbree;  // built before the frames
    std::unique_ptr<RayQueryScene> persistentRayQuery;  // allocated before the frames; built by the first
    std::vector<double> cameraMs;
    FrameBuffers buffers;
};

struct BenchScene {
    std::string name;  // unique among the run's scenes: rows key on it
    Scene scene;
    std::vector<Bounds> bounds;
    std::vector<Camera> cameras;
    std::string trianglesDigest;
};

BenchScene loadBenchScene(const std::string& path, const BenchCommand& cmd, const std::vector<BenchRow>& rows) {
    BenchScene s;
    s.scene = loadGltf(path);
    const std::string stem = std::filesystem::path(path).stem().string();
    s.name = stem;
    for (int copy = 2; std::any_of(rows.begin(), rows.end(), [&](const BenchRow& r) { return r.scene == s.name; }); ++copy)
        s.name = stem + "_" + std::to_string(copy);
    s.bounds = allTriangleBounds(s.scene.triangles);
    CameraOptions orbit = cmd.camera;
    orbit.orbit = cmd.orbit;
    s.cameras = makeCameras(s.scene, sceneBounds(s.scene.triangles), orbit, double(cmd.width) / double(cmd.height));
    s.trianglesDigest = digestOf(s.scene.triangles.data(), s.scene.triangles.size() * sizeof(Triangle));
    return s;
}

std::vector<Accumulator> startRows(const BenchScene& s, const BenchCommand& cmd, const std::vector<BenchConfig>& configs,
                                   BackendDispatcher& dispatcher) {
    std::vector<Accumulator> acc(configs.size());
    for (std::size_t c = 0; c < configs.size(); ++c) {
        BenchRow& row = acc[c].row;
        row.scene = s.name;
        row.triangles = s.scene.triangleCount();
        row.raysPerFrame = std::size_t(cmd.width) * std::size_t(cmd.height);
        row.cameras = int(s.cameras.size());
        row.config = configs[c];
        row.config.request.embree.imageWidth = std::uint32_t(cmd.width);
        if (configs[c].backend() == Backend::RayQuery)
            acc[c].persistentRayQuery = std::make_unique<RayQueryScene>(*dispatcher.gpuContext(), *dispatcher.pipelines(),
                                                                        s.scene.triangles, configs[c].request.rayQueryBuild);
        if (configs[c].backend() == Backend::Embree) {
            EmbreeOptions embree = row.config.request.embree;
            embree.threads = configs[c].threads();
            acc[c].persistentEmbree = std::make_unique<EmbreeScene>(s.scene.triangles, embree);
        }
    }
    return acc;
}

// Every configuration's frames of one camera. Configurations are interleaved (repeat, then
// configuration), so that a slow spell of this shared machine lands on every configuration
// alike instead of on whichever one happened to run then.
constexpr int kVulkanSettleMs = 200;

void measureCamera(const BenchScene& s, std::size_t k, const BenchCommand& cmd, const std::string& cacheDir,
                   std::vector<Accumulator>& acc, BackendDispatcher& dispatcher, unsigned hardwareThreads,
                   Progress& progress) {
    progress.stage(s.name + ": camera " + std::to_string(k + 1) + " of " + std::to_string(s.cameras.size()) + ", " +
                   std::to_string(acc.size()) + " configurations");
    progress.step(s.name + " float64 reference, camera " + std::to_string(k));
    const Camera& camera = s.cameras[k];
    const std::vector<Ray> rays = primaryRays(camera, cmd.width, cmd.height);
    ThreadPool& pool = dispatcher.pool(hardwareThreads);
    const std::vector<ReferenceHit> reference =
        cachedReference(s.scene, rays, referenceKey(s.trianglesDigest, rays, camera, cmd.width, cmd.height),
                        cmd.useCache ? cacheDir : std::string(), pool);
    std::vector<Hit> asHits(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) asHits[i] = Hit{float(reference[i].t), reference[i].prim, 0.0f, 0.0f};
    const std::vector<std::uint8_t> referenceShaded = shadeImage(s.scene, HitImage{cmd.width, cmd.height, &rays, &asHits});
    const std::size_t frames = s.cameras.size() * std::size_t(cmd.repeat);
    for (int w = 0; w < cmd.warmup + cmd.repeat; ++w) {
        for (Accumulator& a : acc) {
            const BenchConfig& config = a.row.config;
            progress.step(s.name + " " + config.series + " " + config.name + " camera " + std::to_string(k));
            const FrameOutcome frame =
                traceFrame(config, s.scene, camera, cmd.width, cmd.height, dispatcher, a.persistentEmbree.get(),
                           a.persistentRayQuery.get(), a.buffers);
            // lavapipe's worker threads spin on for a while after a dispatch; the next frame, on
            // the same cores, would pay for it (Mesa 25.0.7, Dragon: the ray generation after a gpu
            // frame took 10.7 ms instead of 5.3 with no pause or a 20 ms one, 5.3 with 200 ms;
            // docs/benchmarks.md). An untimed pause lets them go to sleep.
            if (runsOnVulkan(config.backend()))
                std::this_thread::sleep_for(std::chrono::milliseconds(kVulkanSettleMs));
            if (w < cmd.warmup) continue;
            a.cameraMs.push_back(frame.ms);
            for (const auto& [name, ms] : frame.parts) {
                if (!a.partSums.count(name)) a.partOrder.push_back(name);
                a.partSums[name] += ms / double(frames);
            }
            if (w != cmd.warmup) continue;  // every backend is deterministic: one frame's hits stand for all
            const std::vector<std::uint8_t> shaded =
                shadeImage(s.scene, HitImage{cmd.width, cmd.height, &rays, &frame.result.hits});
            a.row.errors.add(measureErrors(s.scene.triangles, s.bounds, rays, reference, frame.result.hits,
                                           referenceShaded, shaded, pool));
            a.row.regions = frame.result.regions;
            a.row.divisionAxis = frame.result.axis;
        }
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
                  BackendDispatcher& dispatcher, unsigned hardwareThreads, std::vector<BenchRow>& rows) {
    const BenchScene s = loadBenchScene(path, cmd, rows);
    std::vector<Accumulator> acc = startRows(s, cmd, configs, dispatcher);
    Progress progress("dacrt bench", s.cameras.size() * (1 + configs.size() * std::size_t(cmd.warmup + cmd.repeat)));
    const std::string cacheDir = cmd.cacheDir.empty() ? defaultCacheDir() : cmd.cacheDir;
    for (std::size_t k = 0; k < s.cameras.size(); ++k)
        measureCamera(s, k, cmd, cacheDir, acc, dispatcher, hardwareThreads, progress);
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

void writeJson(const BenchCommand& cmd, const std::vector<BenchRow>& rows, const BackendDispatcher& dispatcher,
               unsigned hardwareThreads) {
    nlohmann::ordered_json j;
    j["command"] = {{"orbit", cmd.orbit},
                    {"size", std::to_string(cmd.width) + "x" + std::to_string(cmd.height)},
                    {"repeat", cmd.repeat},
                    {"warmup", cmd.warmup},
                    {"suite", toString(cmd.suite)}};
    const gpu::Context* context = dispatcher.gpuContext();
    j["machine"] = {{"cpu", cpuModelName()},
                    {"simd_target", simd::activeTarget()},
                    {"hardware_threads", hardwareThreads},
                    {"gpu_device", context ? context->info().name : std::string()},
                    {"gpu_driver", context ? context->info().driver : std::string()},
                    {"lp_num_threads", std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : ""}};
    j["near_tie_tolerance_relative"] = kNearTieRelativeDepth;
    j["pareto_time_margin"] = kParetoTimeMargin;
    j["validation_errors"] = dispatcher.validationErrors();
    j["rows"] = nlohmann::ordered_json::array();
    for (const BenchRow& r : rows) j["rows"].push_back(rowJson(r));
    writeFileAtomically(cmd.jsonPath, j.dump(2) + "\n");
}

}  // namespace

int runBenchCommand(const BenchCommand& request) {
    const BenchCommand cmd = withOutputs(request);
    checkBenchCommand(cmd);
    const unsigned hardwareThreads = std::max(1u, std::thread::hardware_concurrency());
    const std::vector<Backend> backends = chooseBackends(cmd);
    BackendDispatcher dispatcher(cmd.devices, backends);
    const std::vector<BenchConfig> configs = chooseConfigs(cmd, backends, dispatcher, hardwareThreads);

    std::vector<BenchRow> rows;
    for (const std::string& path : cmd.scenes) measureScene(path, cmd, configs, dispatcher, hardwareThreads, rows);
    compareRows(rows);

    printSummary(rows);
    writeCsv(cmd.csvPath, rows);
    writeJson(cmd, rows, dispatcher, hardwareThreads);
    std::cerr << "dacrt bench: wrote " << cmd.csvPath << " and " << cmd.jsonPath
              << " (plot: python3 tools/bench/plot.py " << cmd.jsonPath << ")\n";
    return dispatcher.validationEpilogue(std::cerr);
}

}  // namespace dacrt
