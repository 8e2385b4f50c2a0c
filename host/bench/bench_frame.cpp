#include "bench/bench_frame.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include "bench/reference_cache.hpp"
#include "core/gltf_loader.hpp"
#include "core/timing.hpp"

namespace dacrt {

void addGpuTimestamps(const TraceResult& r, std::vector<std::pair<std::string, double>>& parts) {
    if (!r.gpu) return;
    double gpuMs = 0.0;
    for (const auto& [name, ms] : r.gpu->dispatchMs) gpuMs += ms;
    parts.emplace_back("gpu timestamps", gpuMs);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

BenchScene loadBenchScene(const std::string& path, const BenchCommand& cmd, const std::vector<std::string>& taken) {
    BenchScene s;
    s.scene = loadGltf(path);
    const std::string stem = std::filesystem::path(path).stem().string();
    s.name = stem;
    for (int copy = 2; std::find(taken.begin(), taken.end(), s.name) != taken.end(); ++copy)
        s.name = stem + "_" + std::to_string(copy);
    s.bounds = allTriangleBounds(s.scene.triangles);
    s.box = sceneBounds(s.scene.triangles);
    CameraOptions orbit = cmd.camera;
    orbit.orbit = cmd.orbit;
    s.cameras = makeCameras(s.scene, s.box, orbit, double(cmd.width) / double(cmd.height));
    s.trianglesDigest = digestOf(s.scene.triangles.data(), s.scene.triangles.size() * sizeof(Triangle));
    return s;
}

PeerScenes makePeerScenes(const BenchConfig& config, const Scene& scene, BackendDispatcher& dispatcher) {
    PeerScenes peers;
    if (config.backend() == Backend::RayQuery) {
        peers.rayQuery = std::make_unique<RayQueryScene>(*dispatcher.gpuContext(), *dispatcher.pipelines(),
                                                         scene.triangles, config.request.rayQueryBuild);
        // A static structure is built once, outside every frame, as Embree's static scene is
        // (a scene builds at its first trace): without it a run with --warmup 0 would time the
        // build in the first frame.
        if (config.request.rayQueryBuild == RayQueryBuild::Static)
            peers.rayQuery->trace({makeRay(glm::vec3(0.0f), glm::dvec3(0.0, 0.0, -1.0))});
    }
    if (config.backend() == Backend::Embree) {
        EmbreeOptions embree = config.request.embree;
        embree.threads = config.threads();
        peers.embree = std::make_unique<EmbreeScene>(scene.triangles, embree);
    }
    return peers;
}

// Embree's scenes persist across frames as its users keep them: a dynamic one is rebuilt each
// frame (vertex buffer updated, committed: a full LOW-quality build into the memory of the last
// one), a refitted one refitted, a static one left alone. The rays and bounds are computed on
// the configuration's threads.
FrameOutcome traceFrame(const BenchConfig& c, const Scene& scene, const Camera& camera, int width, int height,
                        BackendDispatcher& dispatcher, PeerScenes& peers, FrameBuffers& buffers) {
    FrameOutcome out;
    const auto start = Clock::now();
    ThreadPool& pool = dispatcher.pool(c.threads());
    std::vector<Ray>& rays = buffers.rays;
    primaryRays(camera, width, height, pool, rays);
    const bool peer = isPeer(c.backend());
    // Only dacrt's backends read the frame geometry (bounds, scene box, the scan for a shared
    // ray start): the peers' frames do not pay for it.
    if (!peer) {
        Box box;
        triangleBoundsInParallel(scene.triangles, pool, buffers.bounds, box);
        out.geometry = frameGeometry(scene.triangles, buffers.bounds, rays, box, std::uint32_t(width));
        out.geometry.frustum = viewFrustum(camera, width, height);
        out.geometry.trianglesVersion = scene.trianglesVersion;  // an orbit: the triangles stay as they are
    }
    const double prepareMs = msSince(start);
    const auto traceStart = Clock::now();
    if (peers.rayQuery) {
        out.result = peers.rayQuery->trace(rays);
    } else if (peers.embree) {
        const EmbreeBuild build = c.request.embree.build;
        const double updateMs = build == EmbreeBuild::Static ? 0.0 : peers.embree->update();
        out.result = peers.embree->trace(rays, pool);
        if (build != EmbreeBuild::Static)
            (build == EmbreeBuild::Refit ? out.result.phases.refit : out.result.phases.build) = updateMs;
    } else {
        out.result = dispatcher.trace(out.geometry, c.request);
    }
    out.ms = msSince(start);
    out.parts.emplace_back(peer ? "rays" : "rays and bounds", prepareMs);
    out.parts.emplace_back("tracer", msSince(traceStart));
    for (const auto& p : out.result.phases.listed()) out.parts.push_back(p);
    if (out.result.gpu) {
        double gpuMs = 0.0;
        for (const auto& [name, ms] : out.result.gpu->dispatchMs) gpuMs += ms;
        out.parts.emplace_back("gpu timestamps", gpuMs);
    }
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
