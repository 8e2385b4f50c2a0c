#include "cmd/render_stats.hpp"

#include "cmd/json_keys.hpp"

namespace dacrt {
namespace {

nlohmann::ordered_json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

nlohmann::ordered_json renderStatsJson(const RenderOptions& o, const RenderedFrame& frame) {
    const Scene& scene = frame.scene;
    const Camera& camera = frame.camera;
    const TraceResult& r = frame.result;
    const TraceOptions& trace = o.request.trace;
    nlohmann::ordered_json j;
    j["backend"] = toString(trace.backend);
    j["scene"] = o.scenePath;
    j["triangles"] = scene.triangleCount();
    j["triangles_dropped_degenerate"] = scene.degenerateTrianglesDropped;
    j["rays"] = frame.rayCount;
    j["width"] = o.width;
    j["height"] = o.height;
    j["regions"] = r.regions;
    j["threads"] = r.threads;
    j["division_axis"] = r.axis < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(std::string(1, "xyz"[r.axis]));
    j["camera"] = {{"index", frame.cameraIndex}, {"projection", toString(camera.projection)}, {"eye", vec(camera.eye)},
                   {"forward", vec(camera.forward)}, {"up", vec(camera.up)}};
    if (camera.projection == Projection::Perspective) j["camera"]["yfov_degrees"] = glm::degrees(camera.yfovRadians);
    else j["camera"]["ymag"] = camera.ymag;
    if (scene.camera && !scene.camera->name.empty()) j["camera"]["name"] = scene.camera->name;
    const DacrtOptions dacrt = trace.dacrt.resolvedFor(trace.backend);
    j["options"] = {{"ray_limit", dacrt.rayLimit}, {"tri_limit", dacrt.triLimit},
                    {"max_depth", trace.dacrt.maxDepth}, {"split", toString(trace.dacrt.split)},
                    {"axis", toString(trace.axis)}, {"intersector", toString(trace.dacrt.intersector)},
                    {"triangle_filter", toString(trace.dacrt.triangleFilter)},
                    {"precision", toString(trace.dacrt.precision)},
                    {"cull", toString(o.cull)},
                    {"skip_backfaces", trace.skips.backFaces},
                    {"skip_frustum", trace.skips.frustum},
                    {"skip_uploads", trace.skips.uploads},
                    {"skip_subscenes", trace.skips.subScenes}};
    if (trace.backend == Backend::Embree)
        j["options"] = {{"robust", o.request.embree.robust}, {"build", toString(o.request.embree.build)},
                        {"packets", o.request.embree.packets ? "4x4 rtcIntersect16" : "rtcIntersect1"}};
    nlohmann::ordered_json t;
    for (const auto& [name, ms] : frame.timingsMs) t[name] = ms;
    nlohmann::ordered_json phases;
    for (const auto& [name, ms] : r.phaseMs) phases[jsonKey(name)] = ms;
    if (!phases.empty()) t["trace_phases"] = phases;
    if (!r.step1RegionMs.empty()) t["step1_region"] = r.step1RegionMs;
    j["timings_ms"] = t;
    nlohmann::ordered_json mem;
    for (const auto& [name, bytes] : r.memory.buffers) mem[jsonKey(name)] = bytes;
    mem["total"] = r.memory.total();
    j["memory_plan_bytes"] = mem;
    nlohmann::ordered_json work = nlohmann::ordered_json::array();
    work.push_back({{"name", "degenerate triangles dropped at load"}, {"count", frame.scene.degenerateTrianglesDropped},
                    {"why", "no area: never hit"}});
    for (const WorkLine& w : r.memory.work) work.push_back({{"name", w.name}, {"count", w.count}, {"why", w.why}});
    j["work_plan"] = work;
    const Counters& c = r.counters;
    nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < c.terminatedPerRound.size(); ++i)
        rounds.push_back({{"round", c.roundNames[i]}, {"terminated", c.terminatedPerRound[i]}});
    j["counters"] = {{"ray_box_tests", c.rayBoxTests},
                     {"packet_box_tests", c.packetBoxTests},
                     {"ray_triangle_tests", c.rayTriangleTests},
                     {"leaves", c.leaves},
                     {"rays_retired_without_hit", c.raysRetired},
                     {"rays_culled", c.raysCulled},
                     {"rays_terminated_step1", c.terminatedStep1},
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

}  // namespace dacrt
