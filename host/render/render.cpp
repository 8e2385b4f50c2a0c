#include "render/render.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <dacrt/plan_text.hpp>
#include <dacrt/tracer.hpp>

#include "app/exit_codes.hpp"
#include "core/mapped_memory.hpp"
#include "render/frame_pattern.hpp"
#include "app/interrupt_cleanup.hpp"
#include "app/output_paths.hpp"
#include "app/progress.hpp"
#include "render/render_stats.hpp"
#include "app/stale_temporaries.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/image_io.hpp"
#include "core/lights.hpp"
#include "core/shading.hpp"
#include "core/system_memory.hpp"
#include "core/timing.hpp"
#include "library/render_inputs.hpp"

namespace dacrt {
namespace {

// ---- checks, before anything is opened -------------------------------------------------

// Every output the options name, with the option that named it.
std::vector<PlannedOutput> namedOutputs(const RenderOptions& o) {
    return {{"-o", o.outputPath, OutputFormat::Image},
            {"--aov", o.aovPath, OutputFormat::Exr},
            {"--stats", o.statsPath, OutputFormat::Text},
            {"--depth-png", o.depthPngPath, OutputFormat::Image},
            {"--normal-png", o.normalPngPath, OutputFormat::Image}};
}

void checkFrameOptions(const RenderOptions& o) {
    if (o.time && o.frames)
        throw InputError("--time renders one instant and --frames a range of them: give one of the two");
    if (o.fpsGiven && !o.frames)
        throw InputError("--fps times the frames of a range (frame n at n / fps seconds): give --frames FIRST:LAST, or "
                         "--time SECONDS for one instant");
    checkShardRequest(o.shards, o.frames.has_value());
    if (o.skipExisting) {
        bool any = false;
        for (const PlannedOutput& out : namedOutputs(o)) any |= !out.path.empty();
        if (!any)
            throw InputError("--skip-existing skips a frame whose outputs exist: name at least one (-o, --aov, "
                             "--stats, --depth-png, --normal-png)");
    }
}

// The names' frame patterns: one in each name of a range (so that frames do not overwrite one
// another), none without a range. The names themselves are checked once the frames are known
// (checkEveryOutput).
void checkOutputNames(const RenderOptions& o) {
    for (PlannedOutput out : namedOutputs(o)) {
        if (out.path.empty()) continue;
        const bool pattern = checkFramePattern(out.option, out.path);
        if (o.frames && !pattern)
            throw InputError(out.option + " " + out.path +
                             ": a frame range needs a frame number in each output name, e.g. " +
                             suggestFramePattern(out.path) + " (%04d: the frame number padded to 4 digits)");
        if (!o.frames && pattern)
            throw InputError(out.option + " " + out.path + ": a frame number in the name needs a frame range (--frames "
                             "FIRST:LAST); for one instant name the file itself (write %% for a literal percent sign)");
    }
}

void checkRenderOptions(const RenderOptions& o) {
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
    checkTracerOptions(o.tracer);
    checkPassOptions(o.passes);
    checkFrameOptions(o);
    checkOutputNames(o);
    const int strata = int(std::lround(std::sqrt(double(o.samplesPerPixel))));
    if (o.samplesPerPixel < 1 || strata * strata != o.samplesPerPixel || o.samplesPerPixel > 1024)
        throw InputError("--spp " + std::to_string(o.samplesPerPixel) +
                         ": samples per pixel are k x k strata, so a square from 1 to 1024 (1, 4, 9, 16, ...)");
    if (o.samplesPerPixel > 1 && o.outputPath.empty())
        throw InputError("--spp antialiases the shaded image; name it with -o (AOVs keep the pixel centre's sample)");
}

// ---- the schedule: which instants this process renders ----------------------------------

struct FrameSchedule {
    std::vector<FrameInstant> instants;
    Shard shard;
};

FrameSchedule scheduleFrames(const RenderOptions& o) {
    FrameSchedule s;
    s.shard = resolveShard(o.shards, o.frames.has_value(), [](const char* name) { return std::getenv(name); });
    if (!o.frames) {
        s.instants.push_back(FrameInstant{std::nullopt, o.time.value_or(0.0)});
        return s;
    }
    for (std::int64_t n : shardFrames(*o.frames, s.shard)) s.instants.push_back(FrameInstant{n, timeOfFrame(n, o.fps)});
    return s;
}

void announceSchedule(const RenderOptions& o, const FrameSchedule& s) {
    if (!o.frames) return;
    std::cerr << "dacrt: frames " << o.frames->text() << " at " << o.fps << " fps (" << o.frames->count() << " frames)";
    if (s.shard.source.empty()) {
        std::cerr << ", unsharded (no --shard, SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX)\n";
        return;
    }
    std::cerr << "; shard " << s.shard.index << "/" << s.shard.count << " (" << toString(s.shard.mode) << ", from "
              << s.shard.source << "): ";
    if (s.instants.empty()) std::cerr << "no frames; nothing to render\n";
    else std::cerr << "frames " << describeFrames([&] {
        std::vector<std::int64_t> n;
        for (const FrameInstant& i : s.instants) n.push_back(*i.frame);
        return n;
    }()) << "\n";
}

// The files of one instant and camera: the patterns filled in, then "_camN" with an orbit.
struct FrameFiles {
    std::string output, aov, stats, depthPng, normalPng;

    std::vector<std::string> all() const {
        std::vector<std::string> out;
        for (const std::string* p : {&output, &aov, &stats, &depthPng, &normalPng})
            if (!p->empty()) out.push_back(*p);
        return out;
    }
};

int cameraCountOf(const RenderOptions& o) { return std::max(1, o.camera.orbit); }

FrameFiles filesOf(const RenderOptions& o, const FrameInstant& instant, int camera) {
    auto name = [&](const std::string& pattern) {
        if (pattern.empty()) return pattern;
        return pathForCamera(expandFramePattern(pattern, instant.frame.value_or(0)), camera, cameraCountOf(o));
    };
    return {name(o.outputPath), name(o.aovPath), name(o.statsPath), name(o.depthPngPath), name(o.normalPngPath)};
}

// Under --skip-existing: every file of the instant is in place. A file has its final name only
// when complete (OutputBatch), so existing is enough.
bool outputsExist(const RenderOptions& o, const FrameInstant& instant) {
    for (int k = 0; k < cameraCountOf(o); ++k)
        for (const std::string& path : filesOf(o, instant, k).all())
            if (!std::filesystem::is_regular_file(path)) return false;  // a device or FIFO is never done
    return true;
}

// Every file of every frame of the range (every shard's: their names must not meet either) and
// every camera, checked before anything is loaded or written: against the input, one another
// and the file system (app/output_paths.hpp).
void checkEveryOutput(const RenderOptions& o) {
    const std::vector<PlannedOutput> named = namedOutputs(o);
    const std::size_t cameras = std::size_t(cameraCountOf(o));
    const std::size_t perFrame = cameras * named.size();
    const std::size_t frames = o.frames ? std::size_t(o.frames->count()) : 1;
    checkOutputs(
        frames * perFrame,
        [&](std::size_t i) {
            PlannedOutput out = named[i % named.size()];
            if (out.path.empty()) return out;
            const std::int64_t frame = o.frames ? o.frames->frameAt(std::int64_t(i / perFrame)) : 0;
            const int camera = int(i / named.size() % cameras);
            out.path = pathForCamera(expandFramePattern(out.path, frame), camera, int(cameras));
            if (o.frames) out.context = "frame " + std::to_string(frame);
            if (cameras > 1) out.context += (o.frames ? ", camera " : "camera ") + std::to_string(camera);
            return out;
        },
        {o.scenePath});
}

// A killed run's temporaries of this run's names, removed before anything is written.
void removeStaleTemporariesOf(const RenderOptions& o, const FrameSchedule& s) {
    std::vector<std::string> names;
    for (const FrameInstant& instant : s.instants)
        for (int k = 0; k < cameraCountOf(o); ++k)
            for (const std::string& path : filesOf(o, instant, k).all()) names.push_back(path);
    for (const std::string& path : removeStaleTemporaries(names))
        std::cerr << "dacrt: removed " << path << ", left unfinished by a run that was killed\n";
}

// ---- load once ---------------------------------------------------------------------------

struct LoadedDocument {
    GltfDocument document;
    double loadMs = 0.0;
};

LoadedDocument loadDocument(const RenderOptions& o) {
    const auto start = Clock::now();
    LoadedDocument d{GltfDocument::open(o.scenePath), 0.0};
    d.document.checkAnimationChoice(o.animationChoice);
    d.document.setThreads(o.tracer.trace.threads);  // --threads: the flattening's too
    d.loadMs = msSince(start);
    if (o.frames && d.document.animations().empty())
        std::cerr << "dacrt: warning: " << o.scenePath << " has no animations: every frame of the range is the same\n";
    return d;
}

// ---- per frame: evaluate, prepare ----------------------------------------------------------

// What every camera of the instant shares: the scene at that instant, its bounds, the cameras
// and the lights (fixed in the world: a key light follows the first camera only).
struct PreparedScene {
    TraceScene traced;   // the posed scene, moved into the tracer's input (no copy)
    const Scene& scene;  // read through it by the shading and the stats
    const Box& box;      // its triangles'
    std::vector<Camera> cameras;
    std::vector<Light> lights;
    bool headlight = false;
    double evaluateMs = 0.0;
    double prepareMs = 0.0;
};

// The scene flattened at the instant: nodes, morph weights and skins posed by the animations.
// The scene's camera and lights are those of that instant, so an animated camera node moves.
Scene evaluateAnimation(const RenderOptions& o, const GltfDocument& document, const FrameInstant& instant,
                        bool firstFrame) {
    Progress progress("dacrt render", 1);  // on a terminal, a bar while a large scene is flattened
    Scene scene = document.scene(GltfSelection{.scene = o.sceneChoice, .animation = o.animationChoice, .time = instant.time},
                                 [&progress](double done) { progress.fraction(done, "flattening the scene"); });
    selectCamera(scene, o.cameraChoice);
    if (firstFrame)  // every instant has the file's warnings: printed once
        for (const std::string& w : scene.warnings) std::cerr << "dacrt: warning: " << w << "\n";
    const auto cullStart = Clock::now();
    applyCullMode(scene, o.cull);
    scene.setupPhasesMs.emplace_back("cull", msSince(cullStart));
    return scene;
}

PreparedScene prepareFrame(const RenderOptions& o, Scene posed) {
    const Box box = sceneBounds(posed.triangles);
    TraceScene traced = adoptScene(std::move(posed), box);
    const Scene& scene = sceneOf(traced);  // the TraceScene holds it on the heap: moving it keeps these
    const Box& tracedBox = boxOf(traced);
    PreparedScene p{std::move(traced), scene, tracedBox};
    p.cameras = makeCameras(p.scene, p.box, o.camera, double(o.width) / double(o.height));
    p.lights = frameLights(p.scene, p.cameras.front(), p.box, o.passes.lights, p.headlight);
    return p;
}

// ---- per camera: trace, shade, write --------------------------------------------------------

// Prints the plan and stops the frame under --plan; otherwise refuses a plan that exceeds
// this machine's memory.
PlanCallback planCheck(const RenderOptions& o, const PreparedScene& p, std::size_t rays, int cameraIndex) {
    return [&o, &p, rays, cameraIndex](const FramePlan& plan) {
        if (o.planOnly) {
            const std::string frame = toString(o.tracer.trace.backend) + ", " + std::to_string(p.scene.triangleCount()) +
                                      " triangles, " + std::to_string(rays) + " rays" +
                                      (p.cameras.size() > 1 ? ", camera " + std::to_string(cameraIndex) : std::string());
            std::cout << "work plan (" << frame << "):\n"
                      << "  degenerate triangles dropped at load  " << p.scene.degenerateTrianglesDropped
                      << "  (no area: never hit)\n"
                      << describeWork(plan) << "memory plan (" << frame << "):\n"
                      << describeMemory(plan);
            return false;
        }
        checkFitsInMemory("the frame", plan.totalBytes(), "lower --size or --regions");
        return true;
    };
}

// A traced frame: the primary pass and its secondary passes, with their hits as the shade
// stage reads them.
struct TracedFrame {
    RayBatch batch;                  // the primary rays, as the tracer takes them
    const std::vector<Ray>* rays;    // read through it by the shading
    FrameOutput output;
    std::vector<Hit> hits;                   // the primary pass's
    std::vector<std::vector<Hit>> passHits;  // each secondary pass's, in its order
};

std::vector<Hit> shadingHits(const std::vector<RayHit>& hits) {
    std::vector<Hit> out;
    reserveMapped(out, hits.size());
    for (const RayHit& h : hits) out.push_back(Hit{h.t, h.primitive, h.u, h.v});
    return out;
}

// Traces one sample of a camera's frame: the primary rays through `offset` of each pixel, then
// the secondary passes from their hits (seed: the occlusion sequence of this sample).
TracedFrame traceFrame(const RenderOptions& o, const PreparedScene& p, const Camera& camera, glm::dvec2 offset,
                       std::uint32_t seed, Tracer& tracer, const PlanCallback& onPlan,
                       const ProgressCallback& onProgress) {
    TracedFrame f{adoptCameraRays(primaryRays(camera, o.width, o.height, offset), std::uint32_t(o.width),
                                  viewFrustum(camera, o.width, o.height)),
                  nullptr};
    f.rays = &raysOf(f.batch);
    f.output = tracer.traceFrame(p.traced, f.batch, framePasses(p.lights, o.passes, p.box, seed), onPlan, onProgress);
    f.hits = shadingHits(f.output.primary.hits);
    for (const PassOutput& pass : f.output.passes) f.passHits.push_back(shadingHits(pass.output.hits));
    return f;
}

// The shade stage's view of the traced passes (which must outlive it).
Lighting lightingOf(const std::vector<Light>& lights, const TracedFrame& f) {
    Lighting l;
    std::size_t shadow = 0;
    for (std::size_t i = 0; i < f.output.passes.size(); ++i) {
        const FramePass& pass = f.output.passes[i].pass;
        if (pass.kind == PassKind::Occlusion) {
            l.occlusion = &f.passHits[i];
            l.occlusionSamples = pass.raysPerHit;
        } else {
            l.lights.push_back(&lights.at(shadow++));
            l.shadows.push_back(&f.passHits[i]);
        }
    }
    return l;
}

// The shaded image: the centre sample alone, or the mean of k x k strata per pixel (the extra
// samples are traced here, by the same backend, secondary passes included; their time is
// returned in `samplesMs`). The exposure is the centre sample's.
std::vector<std::uint8_t> shadedImage(const RenderOptions& o, const PreparedScene& p, const Camera& camera,
                                      const HitImage& centre, const Lighting& lighting, Tracer& tracer,
                                      double& samplesMs) {
    samplesMs = 0.0;
    if (o.samplesPerPixel == 1) return shadeImage(p.scene, centre, &lighting);
    const auto start = Clock::now();
    const int k = int(std::lround(std::sqrt(double(o.samplesPerPixel))));
    std::vector<glm::vec3> sum;
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            const std::uint32_t seed = std::uint32_t(1 + j * k + i);
            const TracedFrame f = traceFrame(o, p, camera, {(i + 0.5) / k, (j + 0.5) / k}, seed, tracer, {}, {});
            Lighting sample = lightingOf(p.lights, f);
            sample.exposure = lighting.exposure;
            accumulateShading(p.scene, HitImage{o.width, o.height, f.rays, &f.hits}, 1.0f / float(k * k), sum,
                              &sample);
        }
    samplesMs = msSince(start);
    return encodeSrgb8(sum);
}

// The AOV channels of the secondary passes: per light 1 where it reaches the pixel's surface
// unshadowed, else 0; the open fraction of the occlusion rays.
std::vector<AovChannel> visibilityChannels(const Lighting& lighting, std::size_t pixels) {
    std::vector<AovChannel> channels;
    for (std::size_t k = 0; k < lighting.shadows.size(); ++k) {
        AovChannel c{"shadow." + std::to_string(k), std::vector<float>(pixels)};
        for (std::size_t i = 0; i < pixels; ++i) c.values[i] = litBy(lighting, k, i) ? 1.0f : 0.0f;
        channels.push_back(std::move(c));
    }
    if (lighting.occlusion) {
        AovChannel c{"ao", std::vector<float>(pixels)};
        for (std::size_t i = 0; i < pixels; ++i) c.values[i] = openFraction(lighting, i);
        channels.push_back(std::move(c));
    }
    return channels;
}

// The shade and write stages of one camera: each image written to its temporary in `batch`
// (committed with the stats, all or none). Appends the paths to `staged`.
void writeImages(const FrameFiles& files, const PreparedScene& p, const HitImage& image, const Lighting& lighting,
                 const std::vector<std::uint8_t>& shaded, OutputBatch& batch, std::vector<std::string>& staged) {
    auto writeRgb = [&](const std::string& path, const std::vector<std::uint8_t>& rgb) {
        batch.add(path, encodeRgb8(encodingNameFor(path, OutputFormat::Image), image.width, image.height, rgb));
        staged.push_back(path);
    };
    if (!files.output.empty()) writeRgb(files.output, shaded);
    if (!files.aov.empty()) {
        const std::vector<AovChannel> extra = visibilityChannels(lighting, image.hits->size());
        batch.add(files.aov, encodeAov(encodingNameFor(files.aov, OutputFormat::Exr), p.scene, image, extra));
        staged.push_back(files.aov);
    }
    if (!files.depthPng.empty()) writeRgb(files.depthPng, depthPreview(image));
    if (!files.normalPng.empty()) writeRgb(files.normalPng, normalPreview(p.scene, image));
}

void writeStats(const RenderOptions& o, const std::string& path, const RenderedFrame& frame, OutputBatch& batch,
                std::vector<std::string>& staged) {
    if (path.empty()) return;
    batch.add(path, renderStatsJson(o, frame).dump(2) + "\n");
    staged.push_back(path);
}

// What a ray/triangle test costs one thread, measured on the project's 2-core VM (2026-12-01:
// the Bunny at 80x60, 3.7 s on 2 threads with one busy core elsewhere); for estimates only.
constexpr double kBruteNanosecondsPerTest = 15.0;

// Brute force's cost grows with triangles times rays: say so before a long frame.
void announceBruteForce(std::size_t triangles, std::size_t rays, unsigned threads) {
    const double seconds = double(triangles) * double(rays) * kBruteNanosecondsPerTest * 1e-9 / double(threads);
    if (seconds < 3.0) return;
    std::cerr << "dacrt: brute force tests " << triangles << " triangles x " << rays << " rays, about "
              << int(seconds + 0.5) << " s on " << threads << " threads (cpu traces the same image exactly)\n";
}

// Under --plan: what each secondary pass will allocate at most (how many rays it makes
// depends on the primary hits, which --plan does not trace).
void printPassBounds(const RenderOptions& o, const PreparedScene& p, std::size_t primaryRays) {
    for (const FramePass& pass : framePasses(p.lights, o.passes, p.box, 0)) {
        const FramePlan bound = passPlanBound(pass, primaryRays, o.tracer.trace.backend);
        std::cout << "pass '" << pass.name << "', after the primary pass: work plan:\n"
                  << describeWork(bound) << "memory plan (at most; plus the buffers of a pass over every triangle):\n"
                  << describeMemory(bound);
    }
}

// The frame's least memory from the counts alone (frameMemoryBound), checked before its rays
// are made: a size this machine cannot hold is refused at once instead of after its rays have
// filled the memory. Under --plan the bound is printed before the refusal.
void checkFrameBound(const RenderOptions& o, const std::vector<FramePass>& passes) {
    const std::uint64_t pixels = std::uint64_t(o.width) * std::uint64_t(o.height);
    const FramePlan bound = frameMemoryBound(pixels, passes);
    const std::string frame = "a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " frame (" +
                              std::to_string(pixels) + " rays) with " + std::to_string(passes.size()) +
                              (passes.size() == 1 ? " secondary pass" : " secondary passes");
    try {
        checkFitsInMemory(frame + ", in its rays and hits alone,", bound.totalBytes(),
                          "lower --size" + std::string(o.passes.occlusionSamples ? " or --ao" : ""));
    } catch (const InputError&) {
        if (o.planOnly)
            std::cout << "memory plan (at least, from the counts alone: " << frame << "; no ray was made):\n"
                      << describeMemory(bound);
        throw;
    }
}

// The stages of a frame, in ms, in the order --stats and the summary list them.
struct StageTimes {
    double evaluate = 0.0, prepare = 0.0, trace = 0.0, secondary = 0.0, write = 0.0, total = 0.0;

    static constexpr const char* kNames[] = {"evaluate_animation", "prepare", "trace", "secondary_passes", "write",
                                             "total"};
    std::array<double, 6> values() const { return {evaluate, prepare, trace, secondary, write, total}; }
};

// What a run has done so far, for its last lines.
struct RenderTally {
    std::vector<std::string> written;
    std::vector<double> cameraTraceMs;    // one per camera and instant
    std::vector<StageTimes> frameTimes;   // one per instant rendered (cameras summed)
    std::size_t raysPerFrame = 0;
    std::size_t skipped = 0;
    bool bruteAnnounced = false;
};

// "frame 12 (0.5 s): " for a frame of a range, "0.5 s: " for --time, nothing otherwise.
std::string instantLabel(const RenderOptions& o, const FrameInstant& instant) {
    std::ostringstream s;
    if (instant.frame) s << "frame " << *instant.frame << " (" << instant.time << " s): ";
    else if (o.time) s << instant.time << " s: ";
    return s.str();
}

// One camera of an instant: trace (primary pass, then the secondary passes), shade, write the
// images and the stats. Returns the camera's stage times (evaluate and prepare: the caller's).
StageTimes renderCamera(const RenderOptions& o, const PreparedScene& p, int k, const FrameInstant& instant,
                        double sharedMs, const std::vector<std::pair<std::string, double>>& sharedTimings,
                        Tracer& tracer, RenderTally& tally) {
    StageTimes t;
    const Camera& camera = p.cameras[std::size_t(k)];
    const auto cameraStart = Clock::now();
    const std::size_t pixels = std::size_t(o.width) * std::size_t(o.height);
    const bool brute = o.tracer.trace.backend == Backend::Brute;
    const std::vector<FramePass> passes = framePasses(p.lights, o.passes, p.box, 0);
    checkFrameBound(o, passes);
    std::size_t frameRays = pixels;
    for (const FramePass& pass : passes) frameRays += pixels * pass.raysPerHit;
    if (brute && !o.planOnly && !tally.bruteAnnounced) {
        announceBruteForce(p.scene.triangleCount(), frameRays, traceThreads(o.tracer.trace));
        tally.bruteAnnounced = true;
    }
    Progress progress("dacrt render", 1);
    const auto traceStart = Clock::now();
    const TracedFrame frame = traceFrame(o, p, camera, {0.5, 0.5}, 0, tracer, planCheck(o, p, pixels, k),
                                         brute ? ProgressCallback([&](double f) { progress.fraction(f, "brute force"); })
                                               : ProgressCallback());
    if (o.planOnly) {
        printPassBounds(o, p, pixels);
        return t;
    }
    // Pipeline compilation is a cost of the process, not of the frame: reported apart.
    double compileMs = frame.output.primary.timings.pipelineCompileMs;
    for (const PassOutput& pass : frame.output.passes) {
        t.secondary += pass.ms - pass.output.timings.pipelineCompileMs;
        compileMs += pass.output.timings.pipelineCompileMs;
    }
    t.trace = msSince(traceStart) - compileMs - t.secondary;  // the primary pass

    const HitImage image{o.width, o.height, frame.rays, &frame.hits};
    Lighting lighting = lightingOf(p.lights, frame);
    lighting.exposure = autoExposure(p.scene, image, lighting.lights);
    double samplesMs = 0.0;
    const std::vector<std::uint8_t> shaded =
        o.outputPath.empty() ? std::vector<std::uint8_t>() : shadedImage(o, p, camera, image, lighting, tracer, samplesMs);
    const FrameFiles files = filesOf(o, instant, k);
    const auto writeStart = Clock::now();
    OutputBatch batch;  // this camera's files: all or none
    std::vector<std::string> staged;
    writeImages(files, p, image, lighting, shaded, batch, staged);
    t.write = msSince(writeStart);
    tally.cameraTraceMs.push_back(t.trace);
    tally.raysPerFrame = frame.rays->size();
    // The instant's shared stages (load: the first instant's) count in its first camera's total.
    t.total = (k == 0 ? sharedMs : 0.0) + msSince(cameraStart);

    std::vector<std::pair<std::string, double>> timings = sharedTimings;
    for (const auto& [name, ms] : std::vector<std::pair<std::string, double>>{
             {"shader_compile", compileMs}, {"trace", t.trace}, {"secondary_passes", t.secondary},
             {"antialiasing_samples", samplesMs}, {"write", t.write}, {"total", t.total}})
        timings.emplace_back(name, ms);
    writeStats(o, files.stats, RenderedFrame{p.scene, camera, k, instant, frame.rays->size(), frame.output.primary,
                                             timings, &frame.output.passes, p.lights, lighting.exposure},
               batch, staged);
    batch.commit();
    tally.written.insert(tally.written.end(), staged.begin(), staged.end());
    t.write = msSince(writeStart);  // the stats file too; --stats records the images' write

    std::cerr << "dacrt: " << instantLabel(o, instant) << toString(o.tracer.trace.backend) << " camera " << k << ": "
              << p.scene.triangleCount() << " triangles, " << frame.rays->size() << " rays";
    for (const PassOutput& pass : frame.output.passes) std::cerr << " + " << pass.rays << " " << pass.pass.name;
    std::cerr << ", trace " << t.trace << " ms";
    if (!frame.output.passes.empty()) std::cerr << " + " << t.secondary << " ms";
    if (instant.frame || o.time)
        std::cerr << "; evaluate_animation " << p.evaluateMs << " ms, prepare " << p.prepareMs << " ms, write "
                  << t.write << " ms, total " << t.total << " ms";
    std::cerr << "\n";
    return t;
}

// One instant, every camera: evaluate the animation, prepare, then each camera's trace, shade
// and write.
void renderInstant(const RenderOptions& o, const LoadedDocument& d, const FrameInstant& instant, bool first,
                   Tracer& tracer, RenderTally& tally) {
    const auto evaluateStart = Clock::now();
    Scene scene = evaluateAnimation(o, d.document, instant, first);
    const double evaluateMs = msSince(evaluateStart);
    const auto prepareStart = Clock::now();
    PreparedScene p = prepareFrame(o, std::move(scene));
    p.evaluateMs = evaluateMs;
    p.prepareMs = msSince(prepareStart);
    const double loadMs = first ? d.loadMs : 0.0;
    const std::vector<std::pair<std::string, double>> shared = {
        {"load", d.loadMs}, {"evaluate_animation", p.evaluateMs}, {"prepare", p.prepareMs}};

    StageTimes frame{p.evaluateMs, p.prepareMs};
    for (int k = 0; k < int(p.cameras.size()); ++k) {
        const StageTimes c =
            renderCamera(o, p, k, instant, loadMs + p.evaluateMs + p.prepareMs, shared, tracer, tally);
        frame.trace += c.trace;
        frame.secondary += c.secondary;
        frame.write += c.write;
        frame.total += c.total;
    }
    frame.total -= loadMs;  // a frame's own cost: the file's parse is the process's
    tally.frameTimes.push_back(frame);
}

// ---- the last lines -------------------------------------------------------------------------

// Under --validate: every validation message; true when there were errors (the command then
// fails with its validation exit code).
bool reportValidationErrors(const RenderOptions& o, const Tracer& tracer) {
    if (!o.tracer.validate || tracer.validationErrors() == 0) return false;
    for (const std::string& m : tracer.validationMessages()) std::cerr << "dacrt: validation " << m << "\n";
    std::cerr << "dacrt: error: " << tracer.validationErrors() << " Vulkan validation errors\n";
    return true;
}

// A range's summary: frames rendered and skipped, then each stage's mean, min and max per frame.
void reportFrames(const RenderOptions& o, const FrameSchedule& s, const RenderTally& tally) {
    if (!o.frames || o.planOnly) return;
    std::cerr << "dacrt: frames: " << tally.frameTimes.size() << " rendered, " << tally.skipped
              << " skipped (every output existed), of " << s.instants.size() << " in this run";
    if (!tally.frameTimes.empty()) {
        std::cerr << "; per frame mean / min / max ms:";
        for (std::size_t stage = 0; stage < std::size(StageTimes::kNames); ++stage) {
            double sum = 0.0, lo = INFINITY, hi = -INFINITY;
            for (const StageTimes& f : tally.frameTimes) {
                const double v = f.values()[stage];
                sum += v;
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            std::cerr << (stage ? ", " : " ") << StageTimes::kNames[stage] << " " << std::fixed << std::setprecision(2)
                      << sum / double(tally.frameTimes.size()) << " / " << lo << " / " << hi << std::defaultfloat;
        }
    }
    std::cerr << "\n";
}

// The orbit's trace times, then every file written (or how to write one).
void reportRender(const RenderOptions& o, const RenderTally& tally) {
    const std::vector<double>& traceMs = tally.cameraTraceMs;
    if (o.camera.orbit > 1 && !traceMs.empty()) {
        double sum = 0.0;
        for (double t : traceMs) sum += t;
        std::cerr << "dacrt: " << traceMs.size() << " cameras, trace mean " << sum / double(traceMs.size())
                  << " ms (min " << *std::min_element(traceMs.begin(), traceMs.end()) << ", max "
                  << *std::max_element(traceMs.begin(), traceMs.end()) << ")\n";
    }
    const std::vector<std::string>& written = tally.written;
    if (written.empty()) {
        if (tally.skipped) {
            std::cerr << "dacrt: wrote nothing: every frame's outputs existed (--skip-existing)\n";
            return;
        }
        std::cerr << "dacrt: traced " << tally.raysPerFrame * traceMs.size() << " rays with "
                  << toString(o.tracer.trace.backend)
                  << " and wrote nothing: name a shaded image with -o OUT.png, AOVs with --aov OUT.exr, "
                     "stats with --stats OUT.json\n";
        return;
    }
    constexpr std::size_t kListed = 12;  // a range's thousands of names would bury the line
    if (written.size() > kListed) {
        std::cerr << "dacrt: wrote " << written.size() << " files, " << written.front() << " to " << written.back()
                  << "\n";
        return;
    }
    std::cerr << "dacrt: wrote";
    for (std::size_t i = 0; i < written.size(); ++i) std::cerr << (i ? ", " : " ") << written[i];
    std::cerr << "\n";
}

}  // namespace

std::string pathForCamera(const std::string& path, int camera, int cameraCount) {
    if (path.empty() || cameraCount <= 1) return path;
    const std::filesystem::path p(path);
    const int digits = int(std::to_string(cameraCount - 1).size());
    std::string index = std::to_string(camera);
    index.insert(0, std::size_t(digits) - index.size(), '0');
    return (p.parent_path() / (p.stem().string() + "_cam" + index + p.extension().string())).string();
}

int runRender(const RenderOptions& o) {
    stopCleanlyOnSignals();  // first: every thread started later inherits the blocked signals
    checkRenderOptions(o);
    const FrameSchedule schedule = scheduleFrames(o);
    checkEveryOutput(o);
    const LoadedDocument document = loadDocument(o);
    announceSchedule(o, schedule);
    if (schedule.instants.empty()) return kExitSuccess;
    removeStaleTemporariesOf(o, schedule);
    Tracer tracer(o.tracer);

    RenderTally tally;
    for (const FrameInstant& instant : schedule.instants) {
        if (o.skipExisting && outputsExist(o, instant)) {
            ++tally.skipped;
            std::cerr << "dacrt: " << instantLabel(o, instant) << "skipped, every output exists\n";
            continue;
        }
        renderInstant(o, document, instant, tally.frameTimes.empty(), tracer, tally);
    }
    const int code = (reportValidationErrors(o, tracer) ? kExitValidation : kExitSuccess);
    reportFrames(o, schedule, tally);
    if (!o.planOnly) reportRender(o, tally);
    return code;
}

}  // namespace dacrt
