#include "cmd/cli.hpp"


#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>

#include "bench/bench.hpp"
#include "app/exit_codes.hpp"
#include "render/frame_range.hpp"
#include "app/output_paths.hpp"
#include "cmd/devices.hpp"
#include "cmd/info.hpp"
#include "render/render.hpp"
#include "stress/stress.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "cpu/backend_options.hpp"
#include "cpu/simd_kernels.hpp"
#include "gpu/vulkan_error.hpp"
#include "oracle/compare.hpp"

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

// An option that takes one of an enum's names (its table in EnumNames): the help lists the
// names, and the value is stored as the enum.
template <typename E>
CLI::Option* addEnumOption(CLI::App* cmd, const std::string& flags, E& target, const std::string& help,
                           const std::vector<std::string>& names = enumNameList<E>()) {
    return cmd
        ->add_option_function<std::string>(
            flags, [&target](const std::string& name) { target = *parseEnum<E>(name); }, help)
        ->check(CLI::IsMember(names))
        ->default_str(toString(target));
}

// A list of backends, each from the Backend name table.
CLI::Option* addBackendListOption(CLI::App* cmd, const std::string& flags, std::vector<Backend>& target,
                                  const std::string& help, const std::vector<std::string>& names) {
    return cmd
        ->add_option_function<std::vector<std::string>>(
            flags,
            [&target](const std::vector<std::string>& list) {
                target.clear();
                for (const std::string& name : list) target.push_back(*parseEnum<Backend>(name));
            },
            help)
        ->check(CLI::IsMember(names))
        ->delimiter(',');
}

std::vector<std::string> dacrtBackendNames() { return {"brute", "cpu-seq", "cpu", "gpu"}; }

// The DACRT options (render's only: bench sweeps them); their help comes from the table.
void addDacrtOptions(CLI::App* cmd, DacrtOptions& o) {
    addEnumOption(cmd, "--split", o.split, "");
    addEnumOption(cmd, "--split-cost", o.splitCost, "");
    const std::string gpu = ", " + std::to_string(kGpuLeafLimit) +
                            " on gpu (off where the leaf balance decides: under the cpu profile if neither limit is given, or with --leaf-balance N)";
    cmd->add_option("--ray-limit", o.rayLimit)
        ->check(CLI::Range(1u, 1u << 30))
        ->default_str(std::to_string(kCpuSimdRayLimit) + " on the cpu backends (" + std::to_string(kCpuLeafLimit) +
                      " with a non-default intersector, filter or precision)" + gpu);
    cmd->add_option("--tri-limit", o.triLimit)
        ->check(CLI::Range(1u, 1u << 30))
        ->default_str(std::to_string(kCpuSimdTriangleLimit) + " on the cpu backends (" + std::to_string(kCpuLeafLimit) +
                      " with a non-default intersector, filter or precision)" + gpu);
    cmd->add_option("--packets", o.packets)->default_str("on");
    cmd->add_option("--tight-boxes", o.tightBoxes)->default_str("on");
    cmd->add_option("--packet-flush", o.packetFlush)
        ->check(CLI::Range(1u, 1u << 30))
        ->default_str(std::to_string(kPacketFlushDefault));
    addEnumOption(cmd, "--intersector", o.intersector, "");
    addEnumOption(cmd, "--triangle-filter", o.triangleFilter, "");
    addEnumOption(cmd, "--precision", o.precision, "");
    addEnumOption(cmd, "--ray-grouping", o.rayGrouping, "");
    addEnumOption(cmd, "--pass-tracing", o.passTracing, "");
}

// The help and heading of render's backend-specific options, from the table that also refuses
// them (cpu/backend_options.hpp): each names its backends, the developers' knobs apart.
void describeBackendOptions(CLI::App* cmd) {
    for (const BackendOption& row : backendOptions())
        cmd->get_option(std::string(row.flag))
            ->description(backendOptionHelp(row))
            ->group(row.advanced ? "Advanced (developer) options" : "Backend options");
}

// The camera options of render and bench, as text until the command runs.
struct CameraText {
    std::string eye, target, up;
    double fov = 0.0;
};

void addCameraOptions(CLI::App* cmd, CameraText& t) {
    cmd->add_option("--eye", t.eye, "camera position x,y,z (default: the scene's camera, else a front view framing the scene)");
    cmd->add_option("--target", t.target, "point the camera looks at x,y,z");
    cmd->add_option("--up", t.up, "camera up vector x,y,z (default: the scene camera's, else +y)");
    cmd->add_option("--fov", t.fov, "vertical field of view in degrees (default: the scene camera's, else 45)");
}

void applyCameraOptions(const CLI::App& cmd, const CameraText& t, CameraOptions& o) {
    if (!t.eye.empty()) o.eye = parseVec3("--eye", t.eye);
    if (!t.target.empty()) o.target = parseVec3("--target", t.target);
    if (!t.up.empty()) o.up = parseVec3("--up", t.up);
    if (cmd.count("--fov")) {
        if (!(t.fov > 0.0 && t.fov < 180.0))
            throw InputError("--fov: the vertical field of view must lie strictly between 0 and 180 degrees, got " +
                             std::to_string(t.fov));
        o.fovDegrees = t.fov;
    }
}

// --no-skip LIST: the skips (options.hpp, Skip) to turn off, to measure what each saves (its
// help: the backend option table's).
void addSkipListOption(CLI::App* cmd, SkipSwitches& skips) {
    cmd->add_option_function<std::vector<std::string>>(
           "--no-skip",
           [&skips](const std::vector<std::string>& list) {
               for (const std::string& name : list) {
                   const Skip skip = *parseEnum<Skip>(name);
                   if (skip == Skip::BackFaces) skips.backFaces = false;
                   if (skip == Skip::Frustum) skips.frustum = false;
                   if (skip == Skip::Uploads) skips.uploads = false;
                   if (skip == Skip::SubScenes) skips.subScenes = false;
                   if (skip == Skip::PassRays) skips.passRays = false;
               }
           },
           "")
        ->check(CLI::IsMember(enumNameList<Skip>()))
        ->delimiter(',');
}

// A subcommand: its options parse into state of its own, and run() is called when it is chosen.
struct Subcommand {
    CLI::App* app = nullptr;
    std::function<int()> run;
};

void addDeviceOptions(CLI::App* cmd, std::string& device, bool& validate) {
    cmd->add_option("--device", device, "Vulkan device index or part of its name, see 'dacrt devices' (gpu, rayquery; default: discrete, integrated, then the rest)");
    cmd->add_flag("--validate", validate, "run under the Vulkan validation layers; errors fail the run with exit 3 (gpu, rayquery)");
}

// render's instants and their shards (docs/animation.md): the values as text, parsed by
// applyFrameOptions when the command runs.
template <typename State>
void addFrameOptions(CLI::App* cmd, State& s) {
    RenderOptions& render = s.render;
    cmd->add_option("--time", s.time, "render the scene at this instant of its animations, in seconds (default 0)");
    cmd->add_option("--frames", s.frames,
                    "render frames FIRST to LAST (inclusive), every STEP-th: FIRST:LAST[:STEP]; frame n is at n / fps "
                    "seconds; every output name needs a frame number pattern (out_%04d.png)");
    cmd->add_option("--fps", s.fps, "frames per second of --frames")->default_str("24");
    cmd->add_option("--animation", render.animationChoice,
                    "which animation plays, by index or name (default: every animation of the file together; "
                    "'dacrt info' lists them)");
    cmd->add_option("--shard", render.shards.shard,
                    "render the I-th of N shards of --frames, I/N with I from 0 (default: from SLURM_ARRAY_TASK_ID "
                    "or JOB_COMPLETION_INDEX, else every frame)");
    cmd->add_option("--shard-mode", s.shardMode,
                    "how a range is split: interleaved (frame k of the range to shard k mod N) or blocked "
                    "(contiguous runs)")
        ->check(CLI::IsMember({"interleaved", "blocked"}))
        ->default_str("interleaved");
    cmd->add_option("--shard-count", render.shards.count,
                    "the number of shards of a Kubernetes Indexed Job (its completions), whose JOB_COMPLETION_INDEX "
                    "gives the shard")
        ->check(CLI::Range(1, kMaxShards));
    cmd->add_flag("--skip-existing", render.skipExisting,
                  "do not render a frame whose every output exists (a re-run finishes the missing frames)");
}

template <typename State>
void applyFrameOptions(const State& s, RenderOptions& r) {
    if (!s.time.empty()) r.time = parseTime(s.time);
    if (!s.frames.empty()) r.frames = parseFrameRange(s.frames);
    r.fpsGiven = !s.fps.empty();
    if (r.fpsGiven) r.fps = parseFps(s.fps);
    r.shards.modeGiven = !s.shardMode.empty();
    r.shards.mode = s.shardMode == "blocked" ? ShardMode::Blocked : ShardMode::Interleaved;
}

Subcommand addRenderCommand(CLI::App& app) {
    struct State {
        RenderOptions render;
        std::string size = "640x480";
        CameraText camera;
        bool embreeFast = false, embreeSingleRays = false;
        std::string time, frames, fps, shardMode;  // parsed when the command runs, errors quoting the text
    };
    auto s = std::make_shared<State>();
    RenderOptions& render = s->render;
    CLI::App* cmd = app.add_subcommand("render", "trace a glTF scene: primary rays, then shadow and occlusion rays");
    cmd->add_option("scene", render.scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    cmd->add_option("--scene", render.sceneChoice, "which of the file's scenes, by index or name (default: the file's default scene; 'dacrt info' lists them)");
    cmd->add_option("--camera", render.cameraChoice, "which camera the scene places, by glTF camera index or name (default: the first; 'dacrt info' lists them)");
    cmd->add_option("-o,--output", render.outputPath, "shaded image (PNG or any OpenImageIO format)");
    cmd->add_option("--aov", render.aovPath, "EXR with depth, normal, primitive id, hit mask, albedo, and per light (shadow.K) and for --ao (ao) the secondary passes' visibility");
    cmd->add_option("--stats", render.statsPath, "JSON with timings, memory plan and counters");
    cmd->add_option("--spp", render.samplesPerPixel,
                    "samples per pixel of the shaded image, k x k strata (1, 4, 9, ...); AOVs keep the pixel centre")
        ->default_str("1");
    cmd->add_option("--light", render.passes.lights,
                    "a light, repeatable: point:X,Y,Z[:CANDELA[:R,G,B]], directional:DX,DY,DZ[:LUX[:R,G,B]] (the way it "
                    "shines), or headlight (the unlit preview, no shadow rays); default: the scene's lights, else a key "
                    "light over the first camera's left shoulder")
        ->expected(1)
        ->allow_extra_args(false)
        ->take_all();
    cmd->add_option("--ao", render.passes.occlusionSamples,
                    "ambient occlusion: rays per primary hit, cosine-distributed (0: none)")
        ->check(CLI::Range(0u, 1024u))->default_str("0");
    cmd->add_option("--ao-distance", render.passes.occlusionDistance,
                    "length of the occlusion rays (default: a tenth of the scene box's diagonal)");
    cmd->add_option("--depth-png", render.depthPngPath, "viewable depth: near bright, far dark, misses black");
    cmd->add_option("--normal-png", render.normalPngPath, "viewable normals: n * 0.5 + 0.5 as RGB, misses black");
    addEnumOption(cmd, "--backend", render.tracer.trace.backend, "tracer");
    cmd->add_option("--size", s->size, "image size WIDTHxHEIGHT")->default_str("640x480");
    // The backend-specific options are added bare: describeBackendOptions gives them their help
    // and heading from the table that also refuses them.
    cmd->add_option("--regions", render.tracer.trace.regions)->check(CLI::Range(1u, 4096u));
    cmd->add_option("--threads", render.tracer.trace.threads)->check(CLI::Range(1u, 1024u));
    addEnumOption(cmd, "--axis", render.tracer.trace.axis, "");
    addDacrtOptions(cmd, render.tracer.trace.dacrt);
    cmd->add_flag("--embree-fast", s->embreeFast);
    cmd->add_flag("--embree-single-rays", s->embreeSingleRays);
    addCameraOptions(cmd, s->camera);
    cmd->add_option("--orbit", render.camera.orbit, "K cameras on a circle about the vertical axis through the scene's centre")
        ->check(CLI::Range(1, 100000))->default_str("1");
    cmd->add_flag("--plan", render.planOnly, "print the work plan (what is traced and skipped) and the memory plan, and stop before tracing");
    addEnumOption(cmd, "--cull", render.cull,
                  "back faces no ray hits: the materials' (glTF doubleSided false: culled), none, or every triangle's");
    addSkipListOption(cmd, render.tracer.trace.skips);
    addDeviceOptions(cmd, render.tracer.device, render.tracer.validate);
    cmd->add_option("--workgroup-size", render.tracer.gpu.workgroupSize)->check(CLI::Range(1u, 1024u));
    cmd->add_option("--ray-groups", render.tracer.gpu.rayGroups)->check(CLI::Range(1u, 64u));
    addEnumOption(cmd, "--gpu-profile", render.tracer.gpu.profile, "");
    cmd->add_flag("--stage-clocks", render.tracer.gpu.stageClocks);
    cmd->add_option("--leaf-balance", render.tracer.gpu.leafBalance)->check(CLI::Range(0u, kMostLeafBalance));
    addFrameOptions(cmd, *s);
    describeBackendOptions(cmd);
    return {cmd, [s, cmd] {
                RenderOptions& r = s->render;
                applyFrameOptions(*s, r);
                parseSize(s->size, r.width, r.height);
                applyCameraOptions(*cmd, s->camera, r.camera);
                r.tracer.embree.robust = !s->embreeFast;
                r.tracer.embree.packets = !s->embreeSingleRays;
                r.tracer.embree.imageWidth = std::uint32_t(r.width);
                return runRender(r);
            }};
}

Subcommand addInfoCommand(CLI::App& app) {
    auto options = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "what a glTF file holds: scenes, cameras, lights, meshes, materials, textures, extensions, bounds");
    cmd->add_option("scene", options->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
    cmd->add_option("--scene", options->sceneChoice, "which of the file's scenes to load and measure, by index or name (default: the file's default scene)");
    return {cmd, [options] { return runInfo(*options); }};
}

Subcommand addDevicesCommand(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("devices", "list the Vulkan devices and the limits that matter here");
    return {cmd, [] { return runDevices(); }};
}

Subcommand addCompareCommand(CLI::App& app) {
    struct State {
        std::string a, b, diff, failOn = "never";
        bool json = false;
        CompareOptions options;
        std::uint64_t maxDiffering = 0;
    };
    auto s = std::make_shared<State>();
    CLI::App* cmd = app.add_subcommand("compare", "compare two --aov images pixel by pixel; with --fail-on, a CI gate");
    cmd->add_option("a", s->a, "first AOV EXR")->required();
    cmd->add_option("b", s->b, "second AOV EXR")->required();
    cmd->add_flag("--json", s->json, "write the report as JSON to stdout");
    cmd->add_option("--tie-bound", s->options.nearTieBound,
                    "relative depth within which a different primitive is a near tie")
        ->check(CLI::PositiveNumber)->default_str(std::to_string(kNearTieRelativeDepth));
    cmd->add_option("--depth-tolerance", s->options.depthTolerance,
                    "relative depth within which the same primitive's depths count as equal (0: bit for bit)")
        ->check(CLI::NonNegativeNumber)->default_str("0");
    cmd->add_option("--fail-on", s->failOn,
                    "exit 1 when the images differ beyond near ties and tolerances (differ), when they are "
                    "not identical (any), or never")
        ->check(CLI::IsMember({"differ", "any", "never"}))->default_str("never");
    cmd->add_option("--max-differing", s->maxDiffering,
                    "with --fail-on differ: pixels allowed to differ beyond near ties and tolerances")
        // CLI11 reads -1 into the unsigned as 2^64 - 1: no limit at all.
        ->check(CLI::Validator([](std::string& v) { return v.starts_with('-') ? "must not be negative, got " + v : std::string(); },
                               "UINT"))
        ->default_str("0");
    cmd->add_option("--diff", s->diff, "PNG of a's surfaces with near ties in yellow and differences in red");
    return {cmd, [s] {
                checkOutputs({{"--diff", s->diff, OutputFormat::Image}}, {s->a, s->b});
                const Aov a = readAov(s->a);  // a before b, so that an error names the first bad file
                const Aov b = readAov(s->b);
                const CompareReport report = compareAovs(a, b, s->options);
                if (!s->diff.empty()) {
                    writeFileAtomically(s->diff, encodeRgb8(encodingNameFor(s->diff, OutputFormat::Image), a.width, a.height, differenceImage(a, report)));
                }
                std::cout << (s->json ? report.json() + "\n" : report.text()) << std::flush;
                if (!s->diff.empty()) std::cerr << "dacrt: wrote " << s->diff << "\n";
                const bool fails = (s->failOn == "any" && report.verdict() != CompareVerdict::Identical) ||
                                   (s->failOn == "differ" && report.realDifferences > s->maxDiffering);
                return int(fails ? kExitCheckFailed : kExitSuccess);
            }};
}

Subcommand addStressCommand(CLI::App& app) {
    struct State {
        StressCommand stress;
        std::string size = "large";
        bool defaultsOnly = false, noDeterminism = false;
    };
    auto s = std::make_shared<State>();
    StressCommand& stress = s->stress;
    CLI::App* cmd = app.add_subcommand("stress", "try to break every backend numerically (docs/stability.md)");
    addBackendListOption(cmd, "--backends", stress.backends, "backends to run (default: brute,cpu-seq,cpu,gpu)",
                         dacrtBackendNames());
    cmd->add_option("--families", stress.families, "case families (default: watertight,split-plane,degenerate,surface-rays)")
        ->check(CLI::IsMember(stressFamilies()))
        ->delimiter(',');
    cmd->add_option("--size", s->size, "small (the test suite's cases) or large")
        ->check(CLI::IsMember({"small", "large"}))->default_str("large");
    cmd->add_option("--seed", stress.seed, "seed of the random parts of the cases")->default_str("1");
    cmd->add_flag("--defaults-only", s->defaultsOnly, "run only each backend's default configuration");
    cmd->add_flag("--no-determinism", s->noDeterminism, "skip the determinism checks");
    cmd->add_option("--json", stress.jsonPath, "write the table and checks as JSON");
    addDeviceOptions(cmd, stress.device, stress.validate);
    return {cmd, [s] {
                s->stress.size = s->size == "small" ? StressSize::Small : StressSize::Large;
                s->stress.withOptions = !s->defaultsOnly;
                s->stress.determinism = !s->noDeterminism;
                return runStressCommand(s->stress);
            }};
}

Subcommand addBenchCommand(CLI::App& app) {
    struct State {
        BenchCommand bench;
        std::string size = "640x480";
        CameraText camera;
        bool noCache = false;
        std::string frames, fps;  // --suite animation, parsed as render parses them
    };
    auto s = std::make_shared<State>();
    BenchCommand& bench = s->bench;
    CLI::App* cmd = app.add_subcommand("bench", "frame time against error for every backend and option (docs/benchmarks.md)");
    cmd->add_option("scenes", bench.scenes, "glTF scenes")->required();
    addBackendListOption(cmd, "--backends", bench.backends,
                         "backends (default: cpu-seq,cpu,gpu,embree,rayquery; gpu with a Vulkan device, "
                         "rayquery with one that has ray query)", enumNameList<Backend>());
    addEnumOption(cmd, "--suite", bench.suite,
                  "sweep (every option value), peers (each DACRT default against every embree and rayquery mode), "
                  "skips (each skip of the work plan off in turn), table51 (the source's Table 5.1 and Figure 5.3), "
                  "passes (a lit frame's primary, shadow and occlusion passes timed apart, checked against cpu-seq) or "
                  "animation (an animated scene's frames: evaluation, each backend's rebuild or refit and trace)");
    CLI::Option* frames = cmd->add_option("--frames", s->frames,
                                          "--suite animation: frames FIRST to LAST (inclusive), every STEP-th: "
                                          "FIRST:LAST[:STEP]; frame n is at n / fps seconds")
                              ->default_str("0:11");
    CLI::Option* fps = cmd->add_option("--fps", s->fps, "--suite animation: frames per second")->default_str("24");
    CLI::Option* animation = cmd->add_option("--animation", bench.animation.animation,
                                             "--suite animation: which animation plays, by index or name (default: "
                                             "every animation of the file together)");
    CLI::Option* light = cmd->add_option("--light", bench.passes.lights,
                                         "--suite passes: a light, repeatable, as render's --light (default: the "
                                         "scene's lights, else a key light over the first camera's left shoulder)")
                             ->expected(1)
                             ->allow_extra_args(false)
                             ->take_all();
    CLI::Option* ao = cmd->add_option("--ao", bench.passes.occlusionSamples,
                                      "--suite passes: occlusion rays per primary hit (0: no occlusion pass)")
                          ->check(CLI::Range(0u, 1024u))
                          ->default_str("4");
    CLI::Option* aoDistance = cmd->add_option("--ao-distance", bench.passes.occlusionDistance,
                                              "--suite passes: length of the occlusion rays (default: a tenth of "
                                              "the scene box's diagonal)");
    cmd->add_option("--orbit", bench.orbit, "K cameras on a circle about the vertical axis")->check(CLI::Range(1, 1000))->default_str("1");
    addCameraOptions(cmd, s->camera);
    cmd->add_option("--size", s->size, "image size WIDTHxHEIGHT")->default_str("640x480");
    cmd->add_option("--repeat", bench.repeat, "timed frames per camera (--suite animation: per frame) and configuration")->check(CLI::Range(1, 1000))->default_str("3");
    cmd->add_option("--warmup", bench.warmup, "untimed frames first (of each camera or frame)")->check(CLI::Range(0, 1000))->default_str("1");
    cmd->add_option("--out", bench.outDir, "directory of the outputs not named below")->default_str("dacrt-bench");
    cmd->add_option("--csv", bench.csvPath, "one row per scene and configuration (default OUT/bench.csv)");
    cmd->add_option("--json", bench.jsonPath,
                    "the rows with their time parts (default OUT/bench.json); tools/bench/plot.py draws them");
    cmd->add_option("--cache", bench.cacheDir, "reference cache directory (default: $XDG_CACHE_HOME/dacrt)");
    cmd->add_flag("--no-cache", s->noCache, "always recompute the float64 reference");
    cmd->add_option("--memory-limit", bench.memoryLimitMiB,
                    "the most memory the run may hold, in MiB (default: 90% of this machine's); where every "
                    "configuration's kept structures do not fit at once, the configurations run one after another")
        ->check(CLI::Range(std::uint64_t(1), std::uint64_t(1) << 40));
    addDeviceOptions(cmd, bench.device, bench.validate);
    addEnumOption(cmd, "--gpu-profile", bench.gpuProfile,
                  "whose defaults the gpu rows take: auto (the device's kind), cpu (a CPU device's) or discrete "
                  "(a discrete GPU's, on any device; docs/gpu.md)");
    return {cmd, [s, cmd, light, ao, aoDistance, frames, fps, animation] {
                if (s->bench.suite != BenchSuite::Passes && (light->count() || ao->count() || aoDistance->count()))
                    throw InputError("--light, --ao and --ao-distance light the frames of --suite passes; the other "
                                     "suites time primary rays alone");
                if (s->bench.suite != BenchSuite::Animation && (frames->count() || fps->count() || animation->count()))
                    throw InputError("--frames, --fps and --animation choose the frames of --suite animation; the "
                                     "other suites trace the scene as loaded");
                if (!s->frames.empty()) s->bench.animation.frames = parseFrameRange(s->frames);
                if (!s->fps.empty()) s->bench.animation.fps = parseFps(s->fps);
                parseSize(s->size, s->bench.width, s->bench.height);
                applyCameraOptions(*cmd, s->camera, s->bench.camera);
                s->bench.useCache = !s->noCache;
                return runBenchCommand(s->bench);
            }};
}

// DACRT_SIMD_TARGET runs the cpu backends' kernels on a named instruction set instead of the
// best one (to compare them on one machine); checked before anything else runs.
void applySimdTargetFromEnvironment() {
    const char* name = std::getenv("DACRT_SIMD_TARGET");
    if (!name || !*name) return;
    const std::vector<std::string> available = simd::availableTargets();
    if (std::find(available.begin(), available.end(), name) == available.end()) {
        std::string list;
        for (const std::string& t : available) list += (list.empty() ? "" : ", ") + t;
        throw InputError(std::string("DACRT_SIMD_TARGET=") + name +
                         " is not an instruction set this binary can run on this machine (it can run " + list + ")");
    }
    simd::forceTarget(name);
}

// Runs the chosen subcommand and maps what it throws to its exit code.
int runReportingErrors(const std::function<int()>& run) {
    try {
        applySimdTargetFromEnvironment();
        return run();
    } catch (const InputError& e) {
        std::cerr << "dacrt: error: " << e.what() << "\n";
        return kExitBadInput;
    } catch (const gpu::VulkanError& e) {
        std::cerr << "dacrt: Vulkan error: " << e.what() << "\n";
        return kExitDeviceFailure;
    } catch (const InternalError& e) {
        std::cerr << "dacrt: internal error: " << e.what() << "\n";
        return kExitInternalError;
    } catch (const std::exception& e) {
        std::cerr << "dacrt: internal error: " << e.what() << " (please report it)\n";
        return kExitInternalError;
    }
}

}  // namespace

int runCli(int argc, char** argv) {
    CLI::App app{"dacrt: divide-and-conquer ray tracing without an acceleration structure"};
    app.require_subcommand(1);
    app.footer(exitCodeHelp());
    const std::vector<Subcommand> commands = {addRenderCommand(app), addInfoCommand(app), addDevicesCommand(app), addCompareCommand(app),
                                              addStressCommand(app), addBenchCommand(app)};
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kExitBadInput;
    }
    for (const Subcommand& c : commands)
        if (*c.app) return runReportingErrors(c.run);
    return kExitBadInput;
}

}  // namespace dacrt
