#include "render.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cpu_tracers.hpp"
#include "embree_tracer.hpp"
#include "errors.hpp"
#include "gltf_loader.hpp"
#include "gpu_tracer.hpp"
#include "image_io.hpp"
#include "timing.hpp"

namespace dacrt {
namespace {

std::uint64_t physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? std::uint64_t(pages) * std::uint64_t(pageSize) : 0;
}

nlohmann::ordered_json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

nlohmann::ordered_json statsJson(const RenderOptions& o, const Scene& scene, const Camera& camera, int cameraIndex,
                                 std::size_t rayCount, const TraceResult& r,
                                 const std::vector<std::pair<std::string, double>>& timings) {
    nlohmann::ordered_json j;
    j["backend"] = toString(o.trace.backend);
    j["scene"] = o.scenePath;
    j["triangles"] = scene.triangleCount();
    j["rays"] = rayCount;
    j["width"] = o.width;
    j["height"] = o.height;
    j["regions"] = r.regions;
    j["threads"] = r.threads;
    j["division_axis"] = r.axis < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(std::string(1, "xyz"[r.axis]));
    j["camera"] = {{"index", cameraIndex}, {"eye", vec(camera.eye)}, {"forward", vec(camera.forward)},
                   {"up", vec(camera.up)}, {"yfov_degrees", glm::degrees(camera.yfovRadians)}};
    const DacrtOptions dacrt = o.trace.dacrt.resolvedFor(o.trace.backend);
    j["options"] = {{"ray_limit", dacrt.rayLimit}, {"tri_limit", dacrt.triLimit},
                    {"max_depth", o.trace.dacrt.maxDepth}, {"split", toString(o.trace.dacrt.split)},
                    {"axis", toString(o.trace.axis)}, {"intersector", toString(o.trace.dacrt.intersector)},
                    {"triangle_filter", toString(o.trace.dacrt.triangleFilter)},
                    {"precision", toString(o.trace.dacrt.precision)}};
    if (o.trace.backend == Backend::Embree) j["options"] = {{"robust", !o.embreeFast}};
    nlohmann::ordered_json t;
    for (const auto& [name, ms] : timings) t[name] = ms;
    nlohmann::ordered_json phases;
    for (const auto& [name, ms] : r.phaseMs) phases[name] = ms;
    if (!phases.empty()) t["trace_phases"] = phases;
    if (!r.step1RegionMs.empty()) t["step1_region"] = r.step1RegionMs;
    j["timings_ms"] = t;
    nlohmann::ordered_json mem;
    for (const auto& [name, bytes] : r.memory.buffers) mem[name] = bytes;
    mem["total"] = r.memory.total();
    j["memory_plan_bytes"] = mem;
    const Counters& c = r.counters;
    nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < c.terminatedPerRound.size(); ++i)
        rounds.push_back({{"round", c.roundNames[i]}, {"terminated", c.terminatedPerRound[i]}});
    j["counters"] = {{"ray_box_tests", c.rayBoxTests},
                     {"ray_triangle_tests", c.rayTriangleTests},
                     {"leaves", c.leaves},
                     {"rays_retired_without_hit", c.raysRetired},
                     {"rays_culled", c.raysCulled},
                     {"rays_terminated_step1", r.gpu ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(c.terminatedStep1)},
                     {"rays_terminated_per_round", rounds},
                     {"transfer_work_items", c.transferWorkItems},
                     {"transfer_work_items_skipped", c.transferWorkItemsSkipped}};
    std::uint64_t hits = 0;
    for (const Hit& h : r.hits) hits += h.prim != kMissPrim;
    j["hits"] = hits;
    if (r.gpu) {
        const GpuReport& g = *r.gpu;
        nlohmann::ordered_json dispatches = nlohmann::ordered_json::array();
        for (const auto& [name, ms] : g.dispatchMs) dispatches.push_back({{"name", name}, {"gpu_ms", ms}});
        j["gpu"] = {{"device", g.device},
                    {"driver", g.driver},
                    {"workgroup_size", g.workgroupSize},
                    {"subgroup_size", g.subgroupSize},
                    {"ray_groups", g.rayGroups},
                    {"dispatches", g.dispatches},
                    {"dispatch_times", dispatches},
                    {"work_items_run", g.workItemsRun},
                    {"work_items_empty", g.workItemsEmpty},
                    {"work_item_slices", g.slices},
                    {"rays_finished", g.raysFinished},
                    {"validation_errors", g.validationErrors}};
    }
    return j;
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
    const auto start = Clock::now();
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
        throw InputError("--size: width and height must lie in 1..16384");
    if (o.trace.backend == Backend::Embree && o.planOnly)
        throw InputError("--plan: embree allocates its BVH itself, so dacrt has no memory plan for it");
    if (o.trace.backend == Backend::Embree && !o.trace.dacrt.exactDefaults())
        throw InputError("--intersector, --triangle-filter and --precision are DACRT options; embree has its own test");
    if (o.trace.backend != Backend::Gpu && (o.workgroupSize || o.rayGroups))
        throw InputError("--workgroup-size and --ray-groups tune the gpu backend; --backend " + toString(o.trace.backend) +
                         " has no workgroups");
    Scene scene = loadGltf(o.scenePath);
    const double loadMs = msSince(start);

    const auto prepareStart = Clock::now();
    const std::vector<Bounds> triangleBounds = allTriangleBounds(scene.triangles);
    const Box box = sceneBounds(scene.triangles);
    const std::vector<Camera> cameras = makeCameras(scene, box, o.camera, double(o.width) / double(o.height));
    const double sharedPrepareMs = msSince(prepareStart);

    const unsigned threads =
        o.trace.backend == Backend::CpuSeq ? 1u
                                           : (o.trace.threads ? o.trace.threads : std::max(1u, std::thread::hardware_concurrency()));
    ThreadPool pool(threads);
    std::unique_ptr<vk::Context> gpu;
    std::unique_ptr<PipelineCache> pipelines;
    if (o.trace.backend == Backend::Gpu) {
        gpu = std::make_unique<vk::Context>(vk::ContextOptions{o.device, o.validate});
        pipelines = std::make_unique<PipelineCache>(*gpu);
    }
    const std::uint64_t memoryLimit = physicalMemoryBytes();

    for (int k = 0; k < int(cameras.size()); ++k) {
        const auto frameStart = Clock::now();
        const auto raysStart = Clock::now();
        const std::vector<Ray> rays = primaryRays(cameras[std::size_t(k)], o.width, o.height);
        const FrameGeometry g = frameGeometry(scene.triangles, triangleBounds, rays, box);
        const double prepareMs = sharedPrepareMs + msSince(raysStart);

        auto onPlan = [&](const MemoryPlan& plan) {
            if (o.planOnly) {
                std::cout << "memory plan (" << toString(o.trace.backend) << ", " << scene.triangleCount()
                          << " triangles, " << rays.size() << " rays"
                          << (cameras.size() > 1 ? ", camera " + std::to_string(k) : std::string()) << "):\n"
                          << plan.describe();
                return false;
            }
            if (memoryLimit && plan.total() > memoryLimit)
                throw InputError("the frame needs " + std::to_string(plan.total()) + " bytes but this machine has " +
                                 std::to_string(memoryLimit) + " bytes of memory (over by " +
                                 std::to_string(plan.total() - memoryLimit) + " bytes); lower --size or --regions");
            return true;
        };
        const auto traceStart = Clock::now();
        TraceResult result;
        if (gpu)
            result = traceGpu(g, o.trace, GpuTuning{o.workgroupSize, o.rayGroups}, *gpu, pool, onPlan, pipelines.get());
        else if (o.trace.backend == Backend::Embree)
            result = traceEmbree(g, EmbreeOptions{!o.embreeFast, threads}, pool);
        else
            result = traceCpu(g, o.trace, pool, onPlan);
        if (o.planOnly) continue;
        const double traceMs = msSince(traceStart);

        const auto writeStart = Clock::now();
        const HitImage image{o.width, o.height, &rays, &result.hits};
        const std::string out = pathForCamera(o.outputPath, k, int(cameras.size()));
        const std::string aov = pathForCamera(o.aovPath, k, int(cameras.size()));
        if (!out.empty()) writeShaded(out, scene, image);
        if (!aov.empty()) writeAov(aov, scene, image);
        const double writeMs = msSince(writeStart);
        const double totalMs = (k == 0 ? loadMs : 0.0) + msSince(frameStart) + (k == 0 ? sharedPrepareMs : 0.0);

        const std::string statsPath = pathForCamera(o.statsPath, k, int(cameras.size()));
        const std::vector<std::pair<std::string, double>> timings = {
            {"load", loadMs}, {"prepare", prepareMs}, {"trace", traceMs}, {"write", writeMs}, {"total", totalMs}};
        if (!statsPath.empty()) {
            std::ofstream f(statsPath);
            if (!f) throw InputError(statsPath + ": cannot write the stats file");
            f << statsJson(o, scene, cameras[std::size_t(k)], k, rays.size(), result, timings).dump(2) << "\n";
        }
        std::cerr << "dacrt: " << toString(o.trace.backend) << " camera " << k << ": " << scene.triangleCount()
                  << " triangles, " << rays.size() << " rays, trace " << traceMs << " ms"
                  << (out.empty() ? "" : ", wrote " + out) << "\n";
    }
    if (gpu && o.validate && gpu->validationErrors() > 0) {
        for (const std::string& m : gpu->validationMessages()) std::cerr << "dacrt: validation " << m << "\n";
        std::cerr << "dacrt: error: " << gpu->validationErrors() << " Vulkan validation errors\n";
        return 3;
    }
    return 0;
}

}  // namespace dacrt
