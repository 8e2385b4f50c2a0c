#include "bench/bench_frame.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "bench/reference_cache.hpp"
#include "core/gltf_loader.hpp"
#include "core/timing.hpp"

namespace dacrt {

ThreadPool& ThreadPools::of(unsigned threads) {
    std::unique_ptr<ThreadPool>& p = pools_[threads];
    if (!p) p = std::make_unique<ThreadPool>(threads);
    return *p;
}

void useConfig(Tracer& tracer, const BenchConfig& c) {
    TracerOptions o = c.options;
    o.device = tracer.options().device;
    o.validate = tracer.options().validate;
    tracer.setOptions(o);
}

double prepareStructure(BenchRun& run, const BenchConfig& c, const TraceScene& scene, InLoopEmbree& embree) {
    if (!isPeer(c.backend())) return 0.0;
    if (c.raysInLoop) return embree.build(scene, c);
    useConfig(run.tracer, c);
    const std::vector<float> origin = {0.0f, 0.0f, 0.0f}, direction = {0.0f, 0.0f, -1.0f};
    const RayBatch ray = RayBatch::fromArrays(origin, direction);
    const auto start = Clock::now();
    const TraceOutput built = run.tracer.trace(scene, ray);
    return msSince(start) - built.timings.pipelineCompileMs;
}

std::vector<Hit> hitsOf(const std::vector<RayHit>& hits) {
    std::vector<Hit> out;
    out.reserve(hits.size());
    for (const RayHit& h : hits) out.push_back(Hit{h.t, h.primitive, h.u, h.v});
    return out;
}

void addTraceParts(const TraceOutput& out, std::vector<std::pair<std::string, double>>& parts) {
    for (const TraceTimings::Phase& p : out.timings.phases) parts.emplace_back(p.name, p.ms);
    if (!out.gpu) return;
    double gpuMs = 0.0;
    for (const DeviceReport::Dispatch& d : out.gpu->dispatchTimes) gpuMs += d.gpuMs;
    parts.emplace_back("gpu timestamps", gpuMs);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

BenchScene loadBenchScene(const std::string& path, const BenchCommand& cmd, const std::vector<std::string>& taken) {
    Scene scene = loadGltf(path);
    const std::string stem = std::filesystem::path(path).stem().string();
    std::string name = stem;
    for (int copy = 2; std::find(taken.begin(), taken.end(), name) != taken.end(); ++copy)
        name = stem + "_" + std::to_string(copy);
    const Box box = sceneBounds(scene.triangles);
    BenchScene s{name, adoptScene(std::move(scene), box), {}, box, {}, {}};
    const Scene& loaded = s.scene();
    s.bounds = allTriangleBounds(loaded.triangles);
    CameraOptions orbit = cmd.camera;
    orbit.orbit = cmd.orbit;
    s.cameras = makeCameras(loaded, s.box, orbit, double(cmd.width) / double(cmd.height));
    s.trianglesDigest = digestOf(loaded.triangles.data(), loaded.triangles.size() * sizeof(Triangle));
    return s;
}

RayBatch makeCameraRays(const Camera& camera, int width, int height, ThreadPool& pool, std::vector<Ray>& buffer) {
    primaryRays(camera, width, height, pool, buffer);
    return adoptCameraRays(std::move(buffer), std::uint32_t(width), viewFrustum(camera, width, height));
}

// The peers' structures persist across frames inside the Tracer, as their users keep them: a
// dynamic one is rebuilt each frame (a full LOW-quality build into the memory of the last one),
// a refitted one refitted, a static one left alone (include/dacrt/tracer.hpp). The rays are
// made on the configuration's threads; dacrt's backends compute the triangles' bounds within
// the trace, on its threads.
FrameOutcome traceStillFrame(const BenchConfig& c, const TraceScene& scene, const Camera& camera, int width, int height,
                             BenchRun& run, std::vector<Ray>& rayBuffer, InLoopEmbree& embree) {
    FrameOutcome out;
    if (c.raysInLoop) {
        ThreadPool& pool = run.pools.of(c.threads());
        const auto start = Clock::now();
        PhaseTimes phases = embree.nextFrame();
        phases.add(embree.tracePrimary(camera, width, height, pool));
        out.ms = msSince(start);
        out.output = outputOf(embree.hits(), phases, pool.size(), out.ms);
        addTraceParts(out.output, out.parts);
        return out;
    }
    useConfig(run.tracer, c);
    const auto start = Clock::now();
    RayBatch rays = makeCameraRays(camera, width, height, run.pools.of(c.threads()), rayBuffer);
    const double raysMs = msSince(start);
    const auto traceStart = Clock::now();
    out.output = run.tracer.trace(scene, rays);
    out.ms = msSince(start);
    out.parts.emplace_back("rays", raysMs);
    out.parts.emplace_back("tracer", msSince(traceStart));
    addTraceParts(out.output, out.parts);
    rayBuffer = releaseRays(std::move(rays));
    return out;
}

// lavapipe's worker threads spin on for a while after a dispatch; the next frame, on the same
// cores, would pay for it (Mesa 25.0.7, Dragon: the ray generation after a gpu frame took
// 10.7 ms instead of 5.3 with no pause or a 20 ms one, 5.3 with 200 ms; docs/benchmarks.md).
// An untimed pause lets them go to sleep.
constexpr int kVulkanSettleMs = 200;

void settleAfter(Backend backend) {
    if (runsOnVulkan(backend)) std::this_thread::sleep_for(std::chrono::milliseconds(kVulkanSettleMs));
}

}  // namespace dacrt
