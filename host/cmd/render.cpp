#include "cmd/render.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "cmd/exit_codes.hpp"
#include "cmd/output_paths.hpp"
#include "cmd/progress.hpp"
#include "cmd/render_stats.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/image_io.hpp"
#include "core/lights.hpp"
#include "core/shading.hpp"
#include "core/system_memory.hpp"
#include "core/timing.hpp"

namespace dacrt {
namespace {

void checkRenderOptions(const RenderOptions& o) {
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
    if (o.request.trace.backend == Backend::Embree && o.planOnly)
        throw InputError("--plan: embree allocates its BVH itself, so dacrt has no memory plan for it");
    checkBackendRequest(o.request);
    checkDeviceChoice(o.devices, {o.request.trace.backend});
    checkPassOptions(o.passes);
    // With several cameras the files get "_camN" before the extension, in the same folder.
    checkOutputs({{"-o", o.outputPath, OutputFormat::Image},
                  {"--aov", o.aovPath, OutputFormat::Exr},
                  {"--stats", o.statsPath, OutputFormat::Text},
                  {"--depth-png", o.depthPngPath, OutputFormat::Image},
                  {"--normal-png", o.normalPngPath, OutputFormat::Image}},
                 {o.scenePath});
    const int strata = int(std::lround(std::sqrt(double(o.samplesPerPixel))));
    if (o.samplesPerPixel < 1 || strata * strata != o.samplesPerPixel || o.samplesPerPixel > 1024)
        throw InputError("--spp " + std::to_string(o.samplesPerPixel) +
                         ": samples per pixel are k x k strata, so a square from 1 to 1024 (1, 4, 9, 16, ...)");
    if (o.samplesPerPixel > 1 && o.outputPath.empty())
        throw InputError("--spp antialiases the shaded image; name it with -o (AOVs keep the pixel centre's sample)");
}

// What every camera of the orbit shares: the scene, its bounds, the cameras and the lights
// (fixed in the world: a key light follows the first camera only).
struct PreparedScene {
    Scene scene;
    std::vector<Bounds> triangleBounds;
    Box box;
    std::vector<Camera> cameras;
    std::vector<Light> lights;
    bool headlight = false;
    double loadMs = 0.0;
    double prepareMs = 0.0;
};

PreparedScene loadAndPrepare(const RenderOptions& o) {
    PreparedScene p;
    const auto start = Clock::now();
    p.scene = loadGltf(o.scenePath, {}, GltfSelection{.scene = o.sceneChoice});
    selectCamera(p.scene, o.cameraChoice);
    for (const std::string& w : p.scene.warnings) std::cerr << "dacrt: warning: " << w << "\n";
    applyCullMode(p.scene, o.cull);
    p.loadMs = msSince(start);
    const auto prepareStart = Clock::now();
    p.triangleBounds = allTriangleBounds(p.scene.triangles);
    p.box = sceneBounds(p.scene.triangles);
    p.cameras = makeCameras(p.scene, p.box, o.camera, double(o.width) / double(o.height));
    p.lights = frameLights(p.scene, p.cameras.front(), p.box, o.passes.lights, p.headlight);
    p.prepareMs = msSince(prepareStart);
    return p;
}

// The frame of one camera's rays: the scene's arrays, its view frustum, its triangles' version.
FrameGeometry cameraFrame(const RenderOptions& o, const PreparedScene& p, const Camera& camera,
                          const std::vector<Ray>& rays) {
    FrameGeometry g = frameGeometry(p.scene.triangles, p.triangleBounds, rays, p.box, std::uint32_t(o.width));
    g.frustum = viewFrustum(camera, o.width, o.height);
    g.trianglesVersion = p.scene.trianglesVersion;
    return g;
}

// Prints the plan and stops the frame under --plan; otherwise refuses a plan that exceeds
// this machine's memory.
PlanHook planCheck(const RenderOptions& o, const PreparedScene& p, std::size_t rays, int cameraIndex) {
    return [&o, &p, rays, cameraIndex](const MemoryPlan& plan) {
        if (o.planOnly) {
            const std::string frame = toString(o.request.trace.backend) + ", " + std::to_string(p.scene.triangleCount()) +
                                      " triangles, " + std::to_string(rays) + " rays" +
                                      (p.cameras.size() > 1 ? ", camera " + std::to_string(cameraIndex) : std::string());
            std::cout << "work plan (" << frame << "):\n"
                      << "  degenerate triangles dropped at load  " << p.scene.degenerateTrianglesDropped
                      << "  (no area: never hit)\n"
                      << plan.describeWork() << "memory plan (" << frame << "):\n"
                      << plan.describe();
            return false;
        }
        const std::uint64_t limit = physicalMemoryBytes();
        if (limit && plan.total() > limit)
            throw InputError("the frame needs " + std::to_string(plan.total()) + " bytes but this machine has " +
                             std::to_string(limit) + " bytes of memory (over by " +
                             std::to_string(plan.total() - limit) + " bytes); lower --size or --regions");
        return true;
    };
}

// Pipeline compilation within a trace: a cost of the process, not of the frame.
double compiledMs(const TraceResult& r) {
    double ms = 0.0;
    for (const auto& [name, t] : r.phaseMs)
        if (name == kPipelinePhase) ms += t;
    return ms;
}

// A traced frame: the primary pass and its secondary passes.
struct TracedFrame {
    std::vector<Ray> rays;
    TraceResult primary;
    std::vector<TracedPass> passes;
};

// Traces one sample of a camera's frame: the primary rays through `offset` of each pixel, then
// the secondary passes from their hits (seed: the occlusion sequence of this sample).
TracedFrame traceFrame(const RenderOptions& o, const PreparedScene& p, const Camera& camera, glm::dvec2 offset,
                       std::uint32_t seed, BackendDispatcher& backends, const PlanHook& onPlan, const ProgressHook& onProgress) {
    TracedFrame f;
    f.rays = primaryRays(camera, o.width, o.height, offset);
    const FrameGeometry g = cameraFrame(o, p, camera, f.rays);
    const std::vector<SecondaryPass> passes = secondaryPasses(p.lights, o.passes, p.box, seed);
    BackendRequest request = o.request;
    request.keepForPasses = !passes.empty();
    f.primary = backends.trace(g, request, onPlan, onProgress);
    if (f.primary.hits.empty()) return f;  // stopped at the plan
    f.passes = traceSecondaryPasses(passes, g, f.primary.hits, backends, request, onPlan);
    return f;
}

// The shaded image: the centre sample alone, or the mean of k x k strata per pixel (the extra
// samples are traced here, by the same backend, secondary passes included; their time is
// returned in `samplesMs`). The exposure is the centre sample's.
std::vector<std::uint8_t> shadedImage(const RenderOptions& o, const PreparedScene& p, const Camera& camera,
                                      const HitImage& centre, const Lighting& lighting, BackendDispatcher& backends,
                                      double& samplesMs) {
    samplesMs = 0.0;
    if (o.samplesPerPixel == 1) return shadeImage(p.scene, centre, &lighting);
    const auto start = Clock::now();
    const int k = int(std::lround(std::sqrt(double(o.samplesPerPixel))));
    std::vector<glm::vec3> sum;
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            const std::uint32_t seed = std::uint32_t(1 + j * k + i);
            const TracedFrame f = traceFrame(o, p, camera, {(i + 0.5) / k, (j + 0.5) / k}, seed, backends, {}, {});
            Lighting sample = lightingOf(p.lights, f.passes);
            sample.exposure = lighting.exposure;
            accumulateShading(p.scene, HitImage{o.width, o.height, &f.rays, &f.primary.hits}, 1.0f / float(k * k), sum,
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

// The shade and write stages of one camera, each file complete or absent. Appends the paths
// written to `written`.
void writeImages(const RenderOptions& o, const PreparedScene& p, int k, const HitImage& image, const Lighting& lighting,
                 const std::vector<std::uint8_t>& shaded, std::vector<std::string>& written) {
    const int count = int(p.cameras.size());
    auto writeRgb = [&](const std::string& option, const std::vector<std::uint8_t>& rgb) {
        const std::string path = pathForCamera(option, k, count);
        if (path.empty()) return;
        writeThrough(path, [&](const std::string& to) { writeRgb8(to, image.width, image.height, rgb); });
        written.push_back(path);
    };
    writeRgb(o.outputPath, shaded);
    if (const std::string aov = pathForCamera(o.aovPath, k, count); !aov.empty()) {
        const std::vector<AovChannel> extra = visibilityChannels(lighting, image.hits->size());
        writeThrough(aov, [&](const std::string& to) { writeAov(to, p.scene, image, extra); });
        written.push_back(aov);
    }
    if (!o.depthPngPath.empty()) writeRgb(o.depthPngPath, depthPreview(image));
    if (!o.normalPngPath.empty()) writeRgb(o.normalPngPath, normalPreview(p.scene, image));
}

void writeStats(const RenderOptions& o, int k, int cameraCount, const RenderedFrame& frame,
                std::vector<std::string>& written) {
    const std::string path = pathForCamera(o.statsPath, k, cameraCount);
    if (path.empty()) return;
    writeFileAtomically(path, renderStatsJson(o, frame).dump(2) + "\n");
    written.push_back(path);
}

// Brute force's cost grows with triangles times rays: say so before a long frame.
void announceBruteForce(std::size_t triangles, std::size_t rays, unsigned threads) {
    const double seconds = double(triangles) * double(rays) * kBruteNanosecondsPerTest * 1e-9 / double(threads);
    if (seconds < 3.0) return;
    std::cerr << "dacrt: brute force tests " << triangles << " triangles x " << rays << " rays, about "
              << int(seconds + 0.5) << " s on " << threads << " threads (cpu traces the same image exactly)\n";
}

// The last lines: the orbit's frame times, then every file written (or how to write one).
void reportRender(const RenderOptions& o, const std::vector<double>& traceMs, std::size_t rays,
                  const std::vector<std::string>& written) {
    if (traceMs.size() > 1) {
        double sum = 0.0;
        for (double t : traceMs) sum += t;
        std::cerr << "dacrt: " << traceMs.size() << " cameras, trace mean " << sum / double(traceMs.size())
                  << " ms (min " << *std::min_element(traceMs.begin(), traceMs.end()) << ", max "
                  << *std::max_element(traceMs.begin(), traceMs.end()) << ")\n";
    }
    if (written.empty()) {
        std::cerr << "dacrt: traced " << rays * traceMs.size() << " rays with " << toString(o.request.trace.backend)
                  << " and wrote nothing: name a shaded image with -o OUT.png, AOVs with --aov OUT.exr, "
                     "stats with --stats OUT.json\n";
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

// Under --plan: what each secondary pass will allocate at most (how many rays it makes
// depends on the primary hits, which --plan does not trace).
void printPassBounds(const RenderOptions& o, const PreparedScene& p, std::size_t primaryRays) {
    for (const SecondaryPass& pass : secondaryPasses(p.lights, o.passes, p.box, 0)) {
        const MemoryPlan bound = secondaryPassBound(pass, primaryRays, o.request.trace.backend);
        std::cout << "pass '" << pass.name << "', after the primary pass: work plan:\n"
                  << bound.describeWork() << "memory plan (at most; plus the buffers of a pass over every triangle):\n"
                  << bound.describe();
    }
}

int runRender(const RenderOptions& o) {
    checkRenderOptions(o);
    BackendDispatcher backends(o.devices, {o.request.trace.backend});
    const PreparedScene p = loadAndPrepare(o);

    std::vector<std::string> written;
    std::vector<double> traceTimes;
    std::size_t raysPerFrame = 0;
    for (int k = 0; k < int(p.cameras.size()); ++k) {
        const Camera& camera = p.cameras[std::size_t(k)];
        const auto frameStart = Clock::now();
        const std::size_t pixels = std::size_t(o.width) * std::size_t(o.height);
        const double prepareMs = p.prepareMs;

        const auto traceStart = Clock::now();
        const bool brute = o.request.trace.backend == Backend::Brute;
        const std::vector<SecondaryPass> passes = secondaryPasses(p.lights, o.passes, p.box, 0);
        std::size_t frameRays = pixels;
        for (const SecondaryPass& pass : passes) frameRays += pixels * pass.raysPerHit;
        if (brute && !o.planOnly) announceBruteForce(p.scene.triangleCount(), frameRays, BackendDispatcher::threadsOf(o.request.trace));
        Progress progress("dacrt render", 1);
        const TracedFrame frame = traceFrame(o, p, camera, {0.5, 0.5}, 0, backends, planCheck(o, p, pixels, k),
                                             brute ? ProgressHook([&](double f) { progress.fraction(f, "brute force"); })
                                                   : ProgressHook());
        if (o.planOnly) {
            printPassBounds(o, p, pixels);
            continue;
        }
        // Pipeline compilation is a cost of the process, not of the frame: reported apart.
        double compileMs = compiledMs(frame.primary), passesMs = 0.0;
        for (const TracedPass& t : frame.passes) {
            passesMs += t.ms - compiledMs(t.result);
            compileMs += compiledMs(t.result);
        }
        const double traceMs = msSince(traceStart) - compileMs - passesMs;  // the primary pass

        const HitImage image{o.width, o.height, &frame.rays, &frame.primary.hits};
        Lighting lighting = lightingOf(p.lights, frame.passes);
        lighting.exposure = autoExposure(p.scene, image, lighting.lights);
        double samplesMs = 0.0;
        const std::vector<std::uint8_t> shaded =
            o.outputPath.empty() ? std::vector<std::uint8_t>() : shadedImage(o, p, camera, image, lighting, backends, samplesMs);
        const auto writeStart = Clock::now();
        writeImages(o, p, k, image, lighting, shaded, written);
        const double writeMs = msSince(writeStart);
        traceTimes.push_back(traceMs);
        raysPerFrame = frame.rays.size();
        const double totalMs = (k == 0 ? p.loadMs + p.prepareMs : 0.0) + msSince(frameStart);

        writeStats(o, k, int(p.cameras.size()),
                   RenderedFrame{p.scene, camera, k, frame.rays.size(), frame.primary,
                                 {{"load", p.loadMs}, {"prepare", prepareMs}, {"shader_compile", compileMs}, {"trace", traceMs},
                                  {"secondary_passes", passesMs}, {"antialiasing_samples", samplesMs}, {"write", writeMs},
                                  {"total", totalMs}},
                                 &frame.passes, p.lights, lighting.exposure},
                   written);
        std::cerr << "dacrt: " << toString(o.request.trace.backend) << " camera " << k << ": "
                  << p.scene.triangleCount() << " triangles, " << frame.rays.size() << " rays";
        for (const TracedPass& t : frame.passes) std::cerr << " + " << t.rays << " " << t.pass.name;
        std::cerr << ", trace " << traceMs << " ms";
        if (!frame.passes.empty()) std::cerr << " + " << passesMs << " ms";
        std::cerr << "\n";
    }
    const int code = backends.validationEpilogue(std::cerr);
    if (!o.planOnly) reportRender(o, traceTimes, raysPerFrame, written);
    return code;
}

}  // namespace dacrt
