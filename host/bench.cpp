#include "bench.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "camera.hpp"
#include "compare.hpp"
#include "cpu_tracers.hpp"
#include "embree_tracer.hpp"
#include "error_metrics.hpp"
#include "errors.hpp"
#include "gltf_loader.hpp"
#include "gpu_tracer.hpp"
#include "image_io.hpp"
#include "plot.hpp"
#include "reference_tracer.hpp"
#include "timing.hpp"
#include "vk_context.hpp"

namespace dacrt {
namespace {

// Bumped whenever the reference tracer's answers could change, so stale caches are ignored.
constexpr const char* kReferenceVersion = "reference-v1";

// A configuration is dominated when another one of its series has no more error and is
// faster by more than this fraction, or has less error and is no slower. The same
// configuration measured in two runs on this machine differs by up to about 5%
// (docs/benchmarks.md), so closer times are a draw.
constexpr double kParetoTimeMargin = 0.05;

struct BenchConfig {
    Backend backend = Backend::Cpu;
    std::string series;  // backend, or "embree static"
    std::string name;    // "default" or the option values that differ from it
    TraceOptions trace;
    unsigned threads = 1;
    bool embreeRobust = true;
    bool embreeStatic = false;
    std::uint32_t rayGroups = 0;  // gpu: 0 = the device's default
    bool isDefault = false;
};

struct BenchRow {
    std::string scene;
    std::size_t triangles = 0;
    std::size_t raysPerFrame = 0;
    int cameras = 0;
    BenchConfig config;
    unsigned regions = 0;
    int divisionAxis = -1;
    double frameMsMin = 0.0;
    double frameMsMedian = 0.0;
    std::vector<std::pair<std::string, double>> partsMs;  // mean per frame
    ErrorMetrics errors;
    bool pareto = false;
    std::optional<double> speedupOverSequential;
};

std::string optionText(const BenchConfig& c) {
    std::ostringstream s;
    if (c.backend == Backend::Embree) {
        s << "robust=" << (c.embreeRobust ? "on" : "off") << " timing=" << (c.embreeStatic ? "static" : "dynamic");
        return s.str();
    }
    const DacrtOptions d = c.trace.dacrt.resolvedFor(c.backend);
    s << "intersector=" << toString(d.intersector) << " triangle_filter=" << toString(d.triangleFilter)
      << " precision=" << toString(d.precision) << " split=" << toString(d.split) << " ray_limit=" << d.rayLimit
      << " tri_limit=" << d.triLimit << " axis=" << toString(c.trace.axis) << " regions=" << c.trace.regions
      << " threads=" << c.threads;
    if (c.backend == Backend::Gpu) s << " ray_groups=" << (c.rayGroups ? std::to_string(c.rayGroups) : "auto");
    return s.str();
}

BenchConfig baseConfig(Backend b, unsigned hardwareThreads) {
    BenchConfig c;
    c.backend = b;
    c.series = toString(b);
    c.name = "default";
    c.trace.backend = b;
    c.threads = b == Backend::CpuSeq ? 1u : hardwareThreads;
    c.trace.threads = c.threads;
    c.isDefault = true;
    return c;
}

std::vector<BenchConfig> sweepConfigs(Backend b, unsigned hardwareThreads, unsigned gpuDefaultRegions,
                                      std::uint32_t gpuDefaultRayGroups) {
    std::vector<BenchConfig> out;
    const BenchConfig base = baseConfig(b, hardwareThreads);
    auto variant = [&](const std::string& name, auto&& change) {
        BenchConfig c = base;
        c.name = name;
        c.isDefault = false;
        change(c);
        out.push_back(c);
    };
    if (b == Backend::Embree) {
        out.push_back(base);
        BenchConfig s = base;
        s.series = "embree static";
        s.embreeStatic = true;
        out.push_back(s);
        variant("robust=off", [](BenchConfig& c) { c.embreeRobust = false; });
        variant("robust=off", [](BenchConfig& c) {
            c.embreeRobust = false;
            c.embreeStatic = true;
            c.series = "embree static";
        });
        return out;
    }
    out.push_back(base);
    if (b == Backend::Brute) return out;
    const bool cpu = b == Backend::Cpu || b == Backend::CpuSeq;
    if (cpu) {
        variant("intersector=moller-trumbore", [](BenchConfig& c) { c.trace.dacrt.intersector = Intersector::MollerTrumbore; });
        variant("triangle-filter=sat", [](BenchConfig& c) { c.trace.dacrt.triangleFilter = TriangleFilter::Sat; });
        variant("triangle-filter=mora", [](BenchConfig& c) { c.trace.dacrt.triangleFilter = TriangleFilter::Mora; });
        variant("precision=f64", [](BenchConfig& c) { c.trace.dacrt.precision = Precision::F64; });
        variant("split=centroid-mean", [](BenchConfig& c) { c.trace.dacrt.split = SplitMethod::CentroidMean; });
        variant("split=sampled-mean", [](BenchConfig& c) { c.trace.dacrt.split = SplitMethod::SampledMean; });
    }
    const std::uint32_t defaultLimit = base.trace.dacrt.resolvedFor(b).rayLimit;
    const std::vector<std::uint32_t> limits = cpu ? std::vector<std::uint32_t>{4, 8, 16, 32, 64} : std::vector<std::uint32_t>{8, 16, 32, 64, 128};
    for (std::uint32_t l : limits)
        if (l != defaultLimit)
            variant("leaf-limits=" + std::to_string(l), [l](BenchConfig& c) { c.trace.dacrt.rayLimit = c.trace.dacrt.triLimit = l; });
    if (b == Backend::CpuSeq) return out;
    const unsigned defaultRegions = b == Backend::Cpu ? hardwareThreads : gpuDefaultRegions;
    for (unsigned r : {1u, 2u, 4u, 8u, 16u, 64u})
        if (r != defaultRegions)
            variant("regions=" + std::to_string(r), [r](BenchConfig& c) { c.trace.regions = r; });
    for (DivisionAxis a : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z})
        variant("axis=" + toString(a), [a](BenchConfig& c) { c.trace.axis = a; });
    if (b == Backend::Gpu)
        for (std::uint32_t groups : {1u, 2u, 4u})
            if (groups != gpuDefaultRayGroups)
                variant("ray-groups=" + std::to_string(groups), [groups](BenchConfig& c) { c.rayGroups = groups; });
    return out;
}

// The source's Table 5.1 (threads, and two regions per thread) and Figure 5.3 (division axes).
std::vector<BenchConfig> table51Configs(Backend b, unsigned hardwareThreads) {
    std::vector<BenchConfig> out;
    if (b == Backend::CpuSeq) {
        out.push_back(baseConfig(b, hardwareThreads));
        return out;
    }
    auto config = [&](unsigned threads, unsigned regions, DivisionAxis axis) {
        BenchConfig c = baseConfig(b, hardwareThreads);
        c.isDefault = false;
        c.threads = b == Backend::Cpu ? threads : hardwareThreads;
        c.trace.threads = c.threads;
        c.trace.regions = regions;
        c.trace.axis = axis;
        c.name = (b == Backend::Cpu ? "threads=" + std::to_string(threads) + " " : std::string()) +
                 "regions=" + std::to_string(regions) + " axis=" + toString(axis);
        out.push_back(c);
    };
    const DivisionAxis axes[] = {DivisionAxis::Best, DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z};
    if (b == Backend::Cpu) {
        const std::pair<unsigned, unsigned> setups[] = {{1, 1}, {2, 2}, {4, 4}, {1, 2}, {2, 4}, {4, 8}};
        for (const auto& [threads, regions] : setups)
            for (DivisionAxis a : axes) config(threads, regions, a);
    } else if (b == Backend::Gpu) {
        for (unsigned regions : {1u, 2u, 4u, 8u, 16u})
            for (DivisionAxis a : axes)
                if (a == DivisionAxis::Best || regions == 2 || regions == 4) config(0, regions, a);
    } else {
        throw InputError("--suite table51 compares the DACRT backends (cpu-seq, cpu, gpu), not " + toString(b));
    }
    return out;
}

std::uint64_t fnv1a(const void* data, std::size_t bytes) {
    std::uint64_t h = 1469598103934665603ull;
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::string hex16(std::uint64_t h) {
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << h;
    return hex.str();
}

std::string digestOf(const void* data, std::size_t bytes) { return hex16(fnv1a(data, bytes)) + "-" + std::to_string(bytes); }

std::string defaultCacheDir() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/dacrt";
    if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/dacrt";
    return ".dacrt-cache";
}

std::string cameraKey(const Camera& c, int width, int height) {
    std::ostringstream s;
    s << std::setprecision(17) << c.eye.x << "," << c.eye.y << "," << c.eye.z << "|" << c.forward.x << ","
      << c.forward.y << "," << c.forward.z << "|" << c.up.x << "," << c.up.y << "," << c.up.z << "|"
      << c.yfovRadians << "|" << width << "x" << height;
    return s.str();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string withSuffix(const std::string& path, const std::string& suffix) {
    const std::filesystem::path p(path);
    return (p.parent_path() / (p.stem().string() + "_" + suffix + p.extension().string())).string();
}

// The float64 reference of one camera, read from cacheDir when it holds one for `key`, else
// traced (and stored there). An empty cacheDir means no cache.
std::vector<ReferenceHit> cachedReference(const Scene& scene, const std::vector<Ray>& rays, const std::string& key,
                                          const std::string& cacheDir, ThreadPool& pool) {
    std::vector<ReferenceHit> hits;
    const std::string path = cacheDir + "/" + hex16(fnv1a(key.data(), key.size())) + ".ref";
    if (!cacheDir.empty() && readReferenceCache(path, key, rays.size(), scene.triangleCount(), hits)) return hits;
    hits = traceReference(scene.triangles, rays, pool);
    if (cacheDir.empty()) return hits;
    try {
        writeReferenceCache(path, key, hits);
    } catch (const std::exception& e) {  // the run needs no cache, only the reference
        std::cerr << "dacrt bench: warning: reference not cached: " << e.what() << "\n";
    }
    return hits;
}

class Progress {
public:
    Progress(std::size_t total) : total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}
    void step(const std::string& what) {
        ++done_;
        if (!enabled_) return;
        const int width = 30, filled = int(double(width) * double(done_) / double(std::max<std::size_t>(total_, 1)));
        std::cerr << "\r[" << std::string(std::size_t(filled), '=') << std::string(std::size_t(width - filled), ' ')
                  << "] " << done_ << "/" << total_ << " " << what.substr(0, 60) << "\033[K" << std::flush;
    }
    void finish() {
        if (enabled_) std::cerr << "\r\033[K" << std::flush;
    }

private:
    std::size_t total_, done_ = 0;
    bool enabled_;
};

struct Devices {
    std::map<unsigned, std::unique_ptr<ThreadPool>> pools;
    std::unique_ptr<vk::Context> gpu;
    std::unique_ptr<PipelineCache> pipelines;
    ThreadPool& pool(unsigned threads) {
        auto& p = pools[threads];
        if (!p) p = std::make_unique<ThreadPool>(threads);
        return *p;
    }
};

struct FrameOutcome {
    double ms = 0.0;
    std::vector<std::pair<std::string, double>> parts;
    TraceResult result;
};

FrameOutcome traceFrame(const BenchConfig& c, const Scene& scene, const Camera& camera, int width, int height,
                        Devices& devices, const EmbreeScene* staticEmbree) {
    FrameOutcome out;
    ThreadPool& pool = devices.pool(c.threads);
    const auto start = Clock::now();
    const std::vector<Ray> rays = primaryRays(camera, width, height);
    if (c.backend == Backend::Embree) {
        const double raysMs = msSince(start);
        const auto traceStart = Clock::now();
        if (staticEmbree) {
            out.result = staticEmbree->trace(rays, pool);
        } else {
            std::vector<Bounds> noBounds;
            FrameGeometry g = frameGeometry(scene.triangles, noBounds, rays, Box{});
            out.result = traceEmbree(g, EmbreeOptions{c.embreeRobust, c.threads}, pool);
        }
        out.ms = msSince(start);
        out.parts.emplace_back("rays", raysMs);
        out.parts.emplace_back("tracer", msSince(traceStart));
    } else {
        const std::vector<Bounds> bounds = allTriangleBounds(scene.triangles);
        const Box box = sceneBounds(scene.triangles);
        const FrameGeometry g = frameGeometry(scene.triangles, bounds, rays, box);
        const double prepareMs = msSince(start);
        const auto traceStart = Clock::now();
        out.result = c.backend == Backend::Gpu
                         ? traceGpu(g, c.trace, GpuTuning{0, c.rayGroups}, *devices.gpu, pool, {}, devices.pipelines.get())
                         : traceCpu(g, c.trace, pool);
        out.ms = msSince(start);
        out.parts.emplace_back("rays and bounds", prepareMs);
        out.parts.emplace_back("tracer", msSince(traceStart));
    }
    for (const auto& p : out.result.phaseMs) out.parts.push_back(p);
    if (out.result.gpu) {
        double gpuMs = 0.0;
        for (const auto& [name, ms] : out.result.gpu->dispatchMs) gpuMs += ms;
        out.parts.emplace_back("gpu timestamps", gpuMs);
    }
    return out;
}

void markPareto(std::vector<BenchRow>& rows) {
    for (BenchRow& b : rows) {
        b.pareto = true;
        for (const BenchRow& a : rows) {
            if (&a == &b || a.scene != b.scene || a.config.series != b.config.series) continue;
            const double ea = a.errors.realErrorFraction(), eb = b.errors.realErrorFraction();
            const bool clearlyFaster = a.frameMsMin < b.frameMsMin * (1.0 - kParetoTimeMargin);
            if ((ea <= eb && clearlyFaster) || (ea < eb && a.frameMsMin <= b.frameMsMin)) {
                b.pareto = false;
                break;
            }
        }
    }
}

nlohmann::ordered_json rowJson(const BenchRow& r) {
    const ErrorMetrics& e = r.errors;
    nlohmann::ordered_json j;
    j["scene"] = r.scene;
    j["triangles"] = r.triangles;
    j["rays_per_frame"] = r.raysPerFrame;
    j["cameras"] = r.cameras;
    j["backend"] = toString(r.config.backend);
    j["series"] = r.config.series;
    j["config"] = r.config.name;
    j["default"] = r.config.isDefault;
    j["options"] = optionText(r.config);
    j["threads"] = r.config.threads;
    j["regions"] = r.regions;
    j["division_axis"] = r.divisionAxis < 0 ? std::string("-") : std::string(1, "xyz"[r.divisionAxis]);
    j["frame_ms_min"] = r.frameMsMin;
    j["frame_ms_median"] = r.frameMsMedian;
    j["mrays_per_s"] = double(r.raysPerFrame) / (r.frameMsMedian * 1e3);
    j["speedup_over_cpu_seq"] = r.speedupOverSequential ? nlohmann::ordered_json(*r.speedupOverSequential) : nullptr;
    nlohmann::ordered_json parts;
    for (const auto& [name, ms] : r.partsMs) parts[name] = ms;
    j["parts_ms"] = parts;
    j["pixels"] = e.pixels;
    j["differing_prim"] = e.differingPrim;
    j["near_ties"] = e.nearTies;
    j["real_errors"] = e.realErrors;
    j["real_error_fraction"] = e.realErrorFraction();
    j["near_tie_fraction"] = e.pixels ? double(e.nearTies) / double(e.pixels) : 0.0;
    j["leaks"] = e.leaks;
    j["real_leaks"] = e.realLeaks;
    j["spurious_hits"] = e.spuriousHits;
    j["depth_rel_max"] = e.maxRelDepth;
    j["depth_rel_rms"] = e.rmsRelDepth();
    j["psnr_db"] = std::isinf(e.psnr()) ? nlohmann::ordered_json("inf") : nlohmann::ordered_json(e.psnr());
    j["pareto"] = r.pareto;
    return j;
}

void writeCsv(const std::string& path, const std::vector<BenchRow>& rows) {
    std::ofstream f(path);
    if (!f) throw InputError(path + ": cannot write the CSV file");
    const char* columns[] = {"scene", "triangles", "rays_per_frame", "cameras", "backend", "series", "config",
                             "default", "options", "threads", "regions", "division_axis", "frame_ms_min",
                             "frame_ms_median", "mrays_per_s", "speedup_over_cpu_seq", "pixels", "differing_prim",
                             "near_ties", "real_errors", "real_error_fraction", "near_tie_fraction", "leaks",
                             "real_leaks", "spurious_hits", "depth_rel_max", "depth_rel_rms", "psnr_db", "pareto"};
    for (std::size_t i = 0; i < std::size(columns); ++i) f << (i ? "," : "") << columns[i];
    f << "\n";
    for (const BenchRow& r : rows) {
        const nlohmann::ordered_json j = rowJson(r);
        for (std::size_t i = 0; i < std::size(columns); ++i) {
            const nlohmann::ordered_json& v = j[columns[i]];
            f << (i ? "," : "");
            if (v.is_string()) {
                std::string text = v.get<std::string>();
                if (text.find_first_of(",\"") != std::string::npos) {
                    std::string quoted = "\"";
                    for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
                    text = quoted + "\"";
                }
                f << text;
            } else if (v.is_null()) {
                f << "";
            } else {
                f << v.dump();
            }
        }
        f << "\n";
    }
    if (!f.flush()) throw InputError(path + ": cannot write the CSV file");
}

void printSummary(const std::vector<BenchRow>& rows) {
    std::cout << std::left << std::setw(14) << "series" << std::setw(34) << "config" << std::right << std::setw(10)
              << "min ms" << std::setw(10) << "median" << std::setw(8) << "Mray/s" << std::setw(9) << "speedup"
              << std::setw(10) << "real err" << std::setw(10) << "near tie" << std::setw(8) << "leaks" << std::setw(9)
              << "PSNR" << "  pareto\n";
    std::string scene;
    for (const BenchRow& r : rows) {
        if (r.scene != scene) {
            scene = r.scene;
            std::cout << "== " << scene << " (" << r.triangles << " triangles, " << r.cameras << " cameras, "
                      << r.raysPerFrame << " rays per frame)\n";
        }
        const double psnr = r.errors.psnr();
        std::ostringstream speed, ps;
        speed << std::fixed << std::setprecision(2);
        if (r.speedupOverSequential) speed << *r.speedupOverSequential << "x";
        ps << std::fixed << std::setprecision(1);
        if (std::isinf(psnr)) ps << "inf"; else ps << psnr;
        std::cout << std::left << std::setw(14) << r.config.series << std::setw(34)
                  << (r.config.name + (r.config.isDefault ? " *" : "")) << std::right << std::fixed
                  << std::setprecision(1) << std::setw(10) << r.frameMsMin << std::setw(10) << r.frameMsMedian
                  << std::setw(8) << double(r.raysPerFrame) / (r.frameMsMedian * 1e3) << std::setw(9) << speed.str()
                  << std::setw(10) << r.errors.realErrors << std::setw(10) << r.errors.nearTies << std::setw(8)
                  << r.errors.leaks << std::setw(9) << ps.str() << "  " << (r.pareto ? "yes" : "no") << "\n";
    }
    std::cout << "(* = the backend's default; errors are pixels summed over the cameras)\n";
}

// Resolves the output paths and checks that they can be written before anything is timed:
// a long run must not fail at its end.
BenchCommand withOutputs(BenchCommand cmd) {
    auto resolve = [&](std::string& path, const char* name) {
        if (path.empty()) path = (std::filesystem::path(cmd.outDir) / name).string();
        const std::filesystem::path file(path), parent = file.parent_path().empty() ? "." : file.parent_path();
        std::error_code ec;
        std::filesystem::create_directories(parent, ec);
        const bool writable = std::filesystem::exists(file) ? access(path.c_str(), W_OK) == 0
                                                             : access(parent.c_str(), W_OK | X_OK) == 0;
        if (ec || !writable || std::filesystem::is_directory(file))
            throw InputError(path + ": cannot write here" + (ec ? " (" + ec.message() + ")" : std::string()));
    };
    resolve(cmd.csvPath, "bench.csv");
    resolve(cmd.jsonPath, "bench.json");
    resolve(cmd.plotPath, "bench.png");
    return cmd;
}

}  // namespace

int runBenchCommand(const BenchCommand& request) {
    const BenchCommand cmd = withOutputs(request);
    if (cmd.scenes.empty()) throw InputError("bench: name at least one scene");
    if (cmd.orbit < 1 || cmd.repeat < 1 || cmd.warmup < 0) throw InputError("bench: --orbit and --repeat must be >= 1, --warmup >= 0");
    if (cmd.width < 1 || cmd.height < 1 || cmd.width > 16384 || cmd.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
    const unsigned hardwareThreads = std::max(1u, std::thread::hardware_concurrency());

    std::vector<Backend> backends = cmd.backends;
    const bool gpuAvailable = !vk::listDevices().empty();
    if (backends.empty()) {
        backends = {Backend::CpuSeq, Backend::Cpu};
        if (gpuAvailable)
            backends.push_back(Backend::Gpu);
        else
            std::cerr << "dacrt bench: no Vulkan device, so no gpu rows (name --backends gpu to make that an error)\n";
        if (cmd.suite == BenchSuite::Sweep) backends.push_back(Backend::Embree);
    }
    Devices devices;
    unsigned gpuDefaultRegions = 16;
    std::uint32_t gpuDefaultRayGroups = 1;
    if (std::find(backends.begin(), backends.end(), Backend::Gpu) != backends.end()) {
        devices.gpu = std::make_unique<vk::Context>(vk::ContextOptions{cmd.device, cmd.validate});
        devices.pipelines = std::make_unique<PipelineCache>(*devices.gpu);
        gpuDefaultRegions = defaultGpuRegions(devices.gpu->info());
        gpuDefaultRayGroups = defaultRayGroups(devices.gpu->info(), gpuDefaultRegions);
    }
    std::vector<BenchConfig> configs;
    for (Backend b : backends) {
        const std::vector<BenchConfig> more =
            cmd.suite == BenchSuite::Sweep ? sweepConfigs(b, hardwareThreads, gpuDefaultRegions, gpuDefaultRayGroups)
                                           : table51Configs(b, hardwareThreads);
        configs.insert(configs.end(), more.begin(), more.end());
    }

    const std::string cacheDir = cmd.cacheDir.empty() ? defaultCacheDir() : cmd.cacheDir;

    std::vector<BenchRow> rows;
    for (const std::string& scenePath : cmd.scenes) {
        const Scene scene = loadGltf(scenePath);
        std::string sceneName = std::filesystem::path(scenePath).stem().string();
        for (int copy = 2; std::any_of(rows.begin(), rows.end(), [&](const BenchRow& r) { return r.scene == sceneName; }); ++copy)
            sceneName = std::filesystem::path(scenePath).stem().string() + "_" + std::to_string(copy);  // rows key on it
        const Box box = sceneBounds(scene.triangles);
        const std::vector<Bounds> bounds = allTriangleBounds(scene.triangles);
        CameraOptions cameraOptions;
        cameraOptions.orbit = cmd.orbit;
        const std::vector<Camera> cameras = makeCameras(scene, box, cameraOptions, double(cmd.width) / double(cmd.height));
        const std::size_t raysPerFrame = std::size_t(cmd.width) * std::size_t(cmd.height);
        Progress progress(cameras.size() * (1 + configs.size() * std::size_t(cmd.warmup + cmd.repeat)));

        const std::string trianglesDigest =
            digestOf(scene.triangles.data(), scene.triangles.size() * sizeof(Triangle));

        // Configurations are interleaved (camera, then repeat, then configuration), so that a
        // slow spell of this shared machine lands on every configuration alike instead of on
        // whichever one happened to run then.
        struct Accumulator {
            BenchRow row;
            double minSum = 0.0, medianSum = 0.0;
            std::map<std::string, double> partSums;
            std::vector<std::string> partOrder;
            std::unique_ptr<EmbreeScene> staticEmbree;
            std::vector<double> cameraMs;
        };
        std::vector<Accumulator> acc(configs.size());
        for (std::size_t c = 0; c < configs.size(); ++c) {
            BenchRow& row = acc[c].row;
            row.scene = sceneName;
            row.triangles = scene.triangleCount();
            row.raysPerFrame = raysPerFrame;
            row.cameras = int(cameras.size());
            row.config = configs[c];
            if (configs[c].embreeStatic)  // built once: a static scene pays for its BVH outside the frame
                acc[c].staticEmbree =
                    std::make_unique<EmbreeScene>(scene.triangles, EmbreeOptions{configs[c].embreeRobust, configs[c].threads});
        }
        for (std::size_t k = 0; k < cameras.size(); ++k) {
            progress.step(sceneName + " float64 reference, camera " + std::to_string(k));
            const std::vector<Ray> rays = primaryRays(cameras[k], cmd.width, cmd.height);
            // The key holds what the reference depends on: the triangles as loaded and the
            // rays as generated (so a change to the loader or the camera code misses the cache).
            const std::string key = std::string(kReferenceVersion) + "|" + trianglesDigest + "|" +
                                    digestOf(rays.data(), rays.size() * sizeof(Ray)) + "|" +
                                    cameraKey(cameras[k], cmd.width, cmd.height);
            const std::vector<ReferenceHit> reference =
                cachedReference(scene, rays, key, cmd.useCache ? cacheDir : std::string(), devices.pool(hardwareThreads));
            std::vector<Hit> asHits(rays.size());
            for (std::size_t i = 0; i < rays.size(); ++i) asHits[i] = Hit{float(reference[i].t), reference[i].prim, 0.0f, 0.0f};
            const std::vector<std::uint8_t> referenceShaded =
                shadeImage(scene, HitImage{cmd.width, cmd.height, &rays, &asHits});
            for (int w = 0; w < cmd.warmup + cmd.repeat; ++w) {
                for (std::size_t c = 0; c < configs.size(); ++c) {
                    const BenchConfig& config = configs[c];
                    Accumulator& a = acc[c];
                    progress.step(sceneName + " " + config.series + " " + config.name + " camera " + std::to_string(k));
                    const FrameOutcome frame =
                        traceFrame(config, scene, cameras[k], cmd.width, cmd.height, devices, a.staticEmbree.get());
                    if (w < cmd.warmup) continue;
                    a.cameraMs.push_back(frame.ms);
                    for (const auto& [name, ms] : frame.parts) {
                        if (!a.partSums.count(name)) a.partOrder.push_back(name);
                        a.partSums[name] += ms / double(cameras.size() * std::size_t(cmd.repeat));
                    }
                    if (w != cmd.warmup) continue;  // every backend is deterministic: one frame's hits stand for all
                    const std::vector<std::uint8_t> shaded =
                        shadeImage(scene, HitImage{cmd.width, cmd.height, &rays, &frame.result.hits});
                    a.row.errors.add(measureErrors(scene.triangles, bounds, rays, reference, frame.result.hits,
                                                   referenceShaded, shaded, devices.pool(hardwareThreads)));
                    a.row.regions = frame.result.regions;
                    a.row.divisionAxis = frame.result.axis;
                }
            }
            for (Accumulator& a : acc) {
                // Per camera over the repeats, then the mean over the orbit: each camera is its
                // own workload, so its own minimum is the least noisy figure for it.
                a.minSum += *std::min_element(a.cameraMs.begin(), a.cameraMs.end());
                a.medianSum += median(a.cameraMs);
                a.cameraMs.clear();
            }
        }
        for (Accumulator& a : acc) {
            for (const std::string& name : a.partOrder) a.row.partsMs.emplace_back(name, a.partSums[name]);
            a.row.frameMsMin = a.minSum / double(cameras.size());
            a.row.frameMsMedian = a.medianSum / double(cameras.size());
            rows.push_back(std::move(a.row));
        }
        progress.finish();
    }

    for (BenchRow& r : rows)
        for (const BenchRow& s : rows)
            if (s.scene == r.scene && s.config.backend == Backend::CpuSeq && s.config.isDefault)
                r.speedupOverSequential = s.frameMsMedian / r.frameMsMedian;
    markPareto(rows);
    std::uint32_t validationErrors = devices.gpu ? devices.gpu->validationErrors() : 0;

    printSummary(rows);
    writeCsv(cmd.csvPath, rows);
    {
        nlohmann::ordered_json j;
        j["command"] = {{"orbit", cmd.orbit},
                        {"size", std::to_string(cmd.width) + "x" + std::to_string(cmd.height)},
                        {"repeat", cmd.repeat},
                        {"warmup", cmd.warmup},
                        {"suite", cmd.suite == BenchSuite::Sweep ? "sweep" : "table51"}};
        j["machine"] = {{"hardware_threads", hardwareThreads},
                        {"gpu_device", devices.gpu ? devices.gpu->info().name : std::string()},
                        {"lp_num_threads", std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : ""}};
        j["near_tie_tolerance_relative"] = kNearTieRelativeDepth;
        j["pareto_time_margin"] = kParetoTimeMargin;
        j["validation_errors"] = validationErrors;
        j["rows"] = nlohmann::ordered_json::array();
        for (const BenchRow& r : rows) j["rows"].push_back(rowJson(r));
        std::ofstream f(cmd.jsonPath);
        f << j.dump(2) << "\n";
        if (!f.flush()) throw InputError(cmd.jsonPath + ": cannot write the JSON file");
    }
    {
        std::vector<std::string> scenes;
        for (const BenchRow& r : rows)
            if (std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end()) scenes.push_back(r.scene);
        for (const std::string& s : scenes) {
            std::vector<PlotPoint> points;
            for (const BenchRow& r : rows) {
                if (r.scene != s) continue;
                PlotPoint p;
                p.series = r.config.series;
                p.label = r.config.name;
                p.timeMs = r.frameMsMin;
                p.error = r.errors.realErrorFraction();
                p.pareto = r.pareto;
                p.highlighted = r.config.isDefault;
                p.labelled = r.config.isDefault || p.error > 0.0;  // the zero band is crowded
                points.push_back(p);
            }
            const std::string path = scenes.size() > 1 ? withSuffix(cmd.plotPath, s) : cmd.plotPath;
            writeTimeErrorPlot(path, s + ": frame time against error (" + std::to_string(cmd.width) + "x" +
                                         std::to_string(cmd.height) + ", " + std::to_string(cmd.orbit) + " cameras)",
                               "frame time, ms (each camera's min of repeats, mean over the orbit)",
                               "pixels with a real error (fraction)", points);
        }
    }
    std::cerr << "dacrt bench: wrote " << cmd.csvPath << ", " << cmd.jsonPath << " and the plot "
              << cmd.plotPath << (rows.empty() || cmd.scenes.size() == 1 ? "" : " (one per scene)") << "\n";
    if (cmd.validate && validationErrors > 0) {
        for (const std::string& m : devices.gpu->validationMessages()) std::cerr << "dacrt: validation " << m << "\n";
        std::cerr << "dacrt: error: " << validationErrors << " Vulkan validation errors\n";
        return 3;
    }
    return 0;
}

}  // namespace dacrt
