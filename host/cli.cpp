#include "cli.hpp"

#include <cmath>
#include <iostream>
#include <map>
#include <sstream>

#include <CLI/CLI.hpp>

#include "bench.hpp"
#include "compare.hpp"
#include "errors.hpp"
#include "render.hpp"
#include "stress.hpp"
#include "vk_check.hpp"
#include "vk_context.hpp"

namespace dacrt {
namespace {

glm::dvec3 parseVec3(const std::string& option, const std::string& text) {
    std::stringstream s(text);
    std::string part;
    std::vector<double> values;
    while (std::getline(s, part, ',')) {
        try {
            std::size_t used = 0;
            values.push_back(std::stod(part, &used));
            if (used != part.size()) throw std::invalid_argument(part);
        } catch (const std::exception&) {
            throw InputError(option + ": '" + text + "' is not three comma-separated numbers");
        }
    }
    if (values.size() != 3) throw InputError(option + ": '" + text + "' is not three comma-separated numbers");
    for (double v : values)
        if (!std::isfinite(v)) throw InputError(option + ": '" + text + "' has a non-finite value");
    return {values[0], values[1], values[2]};
}

void parseSize(const std::string& text, int& width, int& height) {
    const std::size_t x = text.find('x');
    try {
        std::size_t usedW = 0, usedH = 0;
        if (x == std::string::npos) throw std::invalid_argument(text);
        width = std::stoi(text.substr(0, x), &usedW);
        height = std::stoi(text.substr(x + 1), &usedH);
        if (usedW != x || usedH != text.size() - x - 1) throw std::invalid_argument(text);
    } catch (const std::exception&) {
        throw InputError("--size: '" + text + "' is not WIDTHxHEIGHT");
    }
}

template <typename E>
CLI::CheckedTransformer choices(const std::map<std::string, E>& map) {
    return CLI::CheckedTransformer(map, CLI::ignore_case);
}

std::map<std::string, Backend> dacrtBackends() {
    return {{"brute", Backend::Brute}, {"cpu-seq", Backend::CpuSeq}, {"cpu", Backend::Cpu}, {"gpu", Backend::Gpu}};
}

CLI::CheckedTransformer backendChoices(bool withEmbree) {
    std::map<std::string, Backend> m = dacrtBackends();
    if (withEmbree) m.emplace("embree", Backend::Embree);
    return choices<Backend>(m);
}

// The DACRT options that render and bench share.
void addDacrtOptions(CLI::App* cmd, DacrtOptions& o) {
    cmd->add_option("--split", o.split, "DACRT split: spatial-median | centroid-mean | sampled-mean")
        ->transform(choices<SplitMethod>({{"spatial-median", SplitMethod::SpatialMedian},
                                          {"centroid-mean", SplitMethod::CentroidMean},
                                          {"sampled-mean", SplitMethod::SampledMean}}))
        ->default_str(toString(DacrtOptions{}.split));
    const std::string limits = std::to_string(kCpuLeafLimit) + " on the cpu backends, " + std::to_string(kGpuLeafLimit) + " on gpu";
    cmd->add_option("--ray-limit", o.rayLimit, "leaf when fewer live rays")
        ->check(CLI::Range(1u, 1u << 30))->default_str(limits);
    cmd->add_option("--tri-limit", o.triLimit, "leaf when fewer triangles")
        ->check(CLI::Range(1u, 1u << 30))->default_str(limits);
    cmd->add_option("--intersector", o.intersector, "leaf ray/triangle test: watertight | moller-trumbore (cpu, cpu-seq)")
        ->transform(choices<Intersector>(
            {{"watertight", Intersector::Watertight}, {"moller-trumbore", Intersector::MollerTrumbore}}))
        ->default_str(toString(DacrtOptions{}.intersector));
    cmd->add_option("--triangle-filter", o.triangleFilter,
                    "triangle/box filter: bounds | sat (exact separating axes) | mora (inexact) (cpu, cpu-seq)")
        ->transform(choices<TriangleFilter>(
            {{"bounds", TriangleFilter::Bounds}, {"sat", TriangleFilter::Sat}, {"mora", TriangleFilter::Mora}}))
        ->default_str(toString(DacrtOptions{}.triangleFilter));
    cmd->add_option("--precision", o.precision, "leaf ray/triangle arithmetic: f32 | f64 (cpu, cpu-seq)")
        ->transform(choices<Precision>({{"f32", Precision::F32}, {"f64", Precision::F64}}))
        ->default_str(toString(DacrtOptions{}.precision));
}

}  // namespace

int runCli(int argc, char** argv) {
    CLI::App app{"dacrt: divide-and-conquer ray tracing without an acceleration structure"};
    app.require_subcommand(1);

    RenderOptions render;
    std::string size = "640x480", eye, target, up;
    double fov = 0.0;
    CLI::App* renderCmd = app.add_subcommand("render", "trace primary rays through a glTF scene");
    renderCmd->add_option("scene", render.scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    renderCmd->add_option("-o,--output", render.outputPath, "shaded image (PNG or any OpenImageIO format)");
    renderCmd->add_option("--aov", render.aovPath, "EXR with depth, normal, primitive id and hit mask");
    renderCmd->add_option("--stats", render.statsPath, "JSON with timings, memory plan and counters");
    renderCmd->add_option("--backend", render.trace.backend, "brute | cpu-seq | cpu | gpu | embree")
        ->transform(backendChoices(true))
        ->default_str("cpu");
    renderCmd->add_option("--size", size, "image size WIDTHxHEIGHT")->default_str("640x480");
    renderCmd->add_option("--regions", render.trace.regions, "sub-scenes of the cpu backend (default: one per thread)")
        ->check(CLI::Range(1u, 4096u));
    renderCmd->add_option("--threads", render.trace.threads, "worker threads (default: every core)")
        ->check(CLI::Range(1u, 1024u));
    renderCmd->add_option("--axis", render.trace.axis, "division axis of the cpu backend: best | x | y | z")
        ->transform(choices<DivisionAxis>(
            {{"best", DivisionAxis::Best}, {"x", DivisionAxis::X}, {"y", DivisionAxis::Y}, {"z", DivisionAxis::Z}}))
        ->default_str("best");
    addDacrtOptions(renderCmd, render.trace.dacrt);
    renderCmd->add_flag("--embree-fast", render.embreeFast, "embree: without RTC_SCENE_FLAG_ROBUST (faster, leaks through edges)");
    renderCmd->add_option("--eye", eye, "camera position x,y,z");
    renderCmd->add_option("--target", target, "point the camera looks at x,y,z");
    renderCmd->add_option("--up", up, "camera up vector x,y,z");
    renderCmd->add_option("--fov", fov, "vertical field of view in degrees");
    renderCmd->add_option("--orbit", render.camera.orbit, "K cameras on a circle about the vertical axis")
        ->check(CLI::Range(1, 100000));
    renderCmd->add_flag("--plan", render.planOnly, "print the memory plan and stop before tracing");
    renderCmd->add_option("--device", render.device, "gpu: Vulkan device index or part of its name (see 'dacrt devices')");
    renderCmd->add_flag("--validate", render.validate, "gpu: run under the Vulkan validation layers; errors fail the run");
    renderCmd->add_option("--workgroup-size", render.workgroupSize, "gpu: invocations per workgroup (default: per device)")
        ->check(CLI::Range(1u, 1024u));
    renderCmd->add_option("--ray-groups", render.rayGroups,
                          "gpu: work items per region, each a band of its rays with its own copy of the region's "
                          "triangle ids (default: per device)")
        ->check(CLI::Range(1u, 64u));

    CLI::App* devicesCmd = app.add_subcommand("devices", "list the Vulkan devices and the limits that matter here");

    std::string compareA, compareB;
    bool compareJson = false;
    double tieBound = kNearTieRelativeDepth;
    CLI::App* compareCmd = app.add_subcommand("compare", "compare two --aov images pixel by pixel");
    compareCmd->add_option("a", compareA, "first AOV EXR")->required();
    compareCmd->add_option("b", compareB, "second AOV EXR")->required();
    compareCmd->add_flag("--json", compareJson, "write the report as JSON to stdout");
    compareCmd->add_option("--tie-bound", tieBound, "relative depth bound of a near tie")->check(CLI::PositiveNumber);

    StressCommand stress;
    std::string stressSize = "large";
    std::vector<Backend> stressBackends;
    std::vector<std::string> stressFamilyNames;
    bool stressDefaultsOnly = false, stressNoDeterminism = false;
    CLI::App* stressCmd = app.add_subcommand("stress", "try to break every backend numerically (docs/stability.md)");
    stressCmd->add_option("--backends", stressBackends, "backends to run (default: brute cpu-seq cpu gpu)")
        ->transform(backendChoices(false))
        ->delimiter(',');
    stressCmd->add_option("--families", stressFamilyNames, "case families (default: watertight split-plane degenerate)")
        ->check(CLI::IsMember({"watertight", "split-plane", "degenerate"}))
        ->delimiter(',');
    stressCmd->add_option("--size", stressSize, "small (the test suite's cases) or large")
        ->check(CLI::IsMember({"small", "large"}))->default_str("large");
    stressCmd->add_option("--seed", stress.seed, "seed of the random parts of the cases")->default_str("1");
    stressCmd->add_flag("--defaults-only", stressDefaultsOnly, "run only each backend's default configuration");
    stressCmd->add_flag("--no-determinism", stressNoDeterminism, "skip the determinism checks");
    stressCmd->add_option("--json", stress.jsonPath, "write the table and checks as JSON");
    stressCmd->add_option("--device", stress.device, "gpu: Vulkan device index or part of its name");
    stressCmd->add_flag("--validate", stress.validate, "gpu: run under the Vulkan validation layers; errors fail the run");

    BenchCommand bench;
    std::string benchSize = "640x480", benchSuite = "sweep";
    bool benchNoCache = false;
    CLI::App* benchCmd = app.add_subcommand("bench", "frame time against error for every backend and option (docs/benchmarks.md)");
    benchCmd->add_option("scenes", bench.scenes, "glTF scenes")->required();
    benchCmd->add_option("--backends", bench.backends, "backends (default: cpu-seq cpu gpu embree; gpu only with a device)")
        ->transform(backendChoices(true))
        ->delimiter(',');
    benchCmd->add_option("--suite", benchSuite, "sweep (every option value) or table51 (the source's Table 5.1 and Figure 5.3)")
        ->check(CLI::IsMember({"sweep", "table51"}))->default_str("sweep");
    benchCmd->add_option("--orbit", bench.orbit, "K cameras on a circle about the vertical axis")->check(CLI::Range(1, 1000))->default_str("1");
    benchCmd->add_option("--size", benchSize, "image size WIDTHxHEIGHT")->default_str("640x480");
    benchCmd->add_option("--repeat", bench.repeat, "timed frames per camera and configuration")->check(CLI::Range(1, 1000))->default_str("3");
    benchCmd->add_option("--warmup", bench.warmup, "untimed frames first")->check(CLI::Range(0, 1000))->default_str("1");
    benchCmd->add_option("--out", bench.outDir, "directory of the outputs not named below")->default_str("dacrt-bench");
    benchCmd->add_option("--csv", bench.csvPath, "one row per scene and configuration (default OUT/bench.csv)");
    benchCmd->add_option("--json", bench.jsonPath, "the rows with their time parts (default OUT/bench.json)");
    benchCmd->add_option("--plot", bench.plotPath, "PNG of frame time against error per scene, Pareto front marked (default OUT/bench.png)");
    benchCmd->add_option("--cache", bench.cacheDir, "reference cache directory (default: $XDG_CACHE_HOME/dacrt)");
    benchCmd->add_flag("--no-cache", benchNoCache, "always recompute the float64 reference");
    benchCmd->add_option("--device", bench.device, "gpu: Vulkan device index or part of its name");
    benchCmd->add_flag("--validate", bench.validate, "gpu: run under the Vulkan validation layers; errors fail the run");

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return 2;
    }

    try {
        if (*renderCmd) {
            parseSize(size, render.width, render.height);
            if (!eye.empty()) render.camera.eye = parseVec3("--eye", eye);
            if (!target.empty()) render.camera.target = parseVec3("--target", target);
            if (!up.empty()) render.camera.up = parseVec3("--up", up);
            if (renderCmd->count("--fov")) render.camera.fovDegrees = fov;
            return runRender(render);
        }
        if (*benchCmd) {
            parseSize(benchSize, bench.width, bench.height);
            bench.suite = benchSuite == "table51" ? BenchSuite::Table51 : BenchSuite::Sweep;
            bench.useCache = !benchNoCache;
            return runBenchCommand(bench);
        }
        if (*stressCmd) {
            stress.size = stressSize == "small" ? StressSize::Small : StressSize::Large;
            stress.backends = stressBackends;
            stress.families = stressFamilyNames;
            stress.withOptions = !stressDefaultsOnly;
            stress.determinism = !stressNoDeterminism;
            return runStressCommand(stress);
        }
        if (*devicesCmd) {
            const std::vector<vk::DeviceInfo> devices = vk::listDevices();
            if (devices.empty()) std::cout << "no Vulkan devices\n";
            for (const vk::DeviceInfo& d : devices) std::cout << d.describe();
            return 0;
        }
        if (*compareCmd) {
            const Aov a = readAov(compareA);
            const Aov b = readAov(compareB);
            const CompareReport report = compareAovs(a, b, tieBound);
            std::cout << (compareJson ? report.json() + "\n" : report.text());
            return 0;
        }
    } catch (const InputError& e) {
        std::cerr << "dacrt: error: " << e.what() << "\n";
        return 2;
    } catch (const vk::VulkanError& e) {
        std::cerr << "dacrt: Vulkan error: " << e.what() << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "dacrt: internal error: " << e.what() << "\n";
        return 1;
    }
    return 2;
}

}  // namespace dacrt
