#include "render/render_stats.hpp"

#include "app/json_keys.hpp"
#include "core/process_memory.hpp"

namespace dacrt {
namespace {

nlohmann::ordered_json vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

nlohmann::ordered_json countersJson(const TraceCounters& c) {
    nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
    for (const TraceCounters::Round& r : c.transferRounds)
        rounds.push_back({{"round", r.name}, {"terminated", r.raysFinished}});
    return {{"ray_box_tests", c.rayBoxTests},
            {"packet_box_tests", c.packetBoxTests},
            {"ray_triangle_tests", c.rayTriangleTests},
            {"ray_triangle_tests_skipped", c.rayTriangleTestsSkipped},
            {"leaves", c.leaves},
            {"tight_boxes", c.tightBoxes},
            {"rays_retired_without_hit", c.raysFinishedWithoutHit},
            {"rays_culled", c.raysCulled},
            {"rays_terminated_step1", c.raysFinishedStep1},
            {"rays_terminated_per_round", rounds},
            {"transfer_work_items", c.transferWorkItems},
            {"transfer_work_items_skipped", c.transferWorkItemsSkipped}};
}

nlohmann::ordered_json memoryJson(const FramePlan& plan) {
    nlohmann::ordered_json mem;
    for (const FramePlan::Buffer& b : plan.memory) mem[jsonKey(b.name)] = b.bytes;
    mem["total"] = plan.totalBytes();
    return mem;
}

nlohmann::ordered_json workJson(const FramePlan& plan, nlohmann::ordered_json work = nlohmann::ordered_json::array()) {
    for (const FramePlan::Work& w : plan.work) work.push_back({{"name", w.name}, {"count", w.count}, {"why", w.why}});
    return work;
}

nlohmann::ordered_json phasesJson(const TraceTimings& timings) {
    nlohmann::ordered_json phases;
    for (const TraceTimings::Phase& phase : timings.phases) phases[jsonKey(phase.name)] = phase.ms;
    return phases;
}

// The work items of each dispatch and their costs' spread (docs/gpu.md, "Work items and parallelism").
nlohmann::ordered_json workItemsJson(const DeviceReport& g) {
    nlohmann::ordered_json passes = nlohmann::ordered_json::array();
    for (const DeviceReport::WorkPass& p : g.workPasses)
        passes.push_back({{"name", p.name}, {"work_items", p.workItems}, {"cost_max", p.costMax},
                          {"cost_mean", p.costMean}, {"max_over_mean", p.costMean > 0.0 ? double(p.costMax) / p.costMean : 0.0}});
    return {{"passes", passes}, {"cost_total", g.workCost}, {"longest_chain_cost", g.longestChainCost},
            {"parallelism", g.parallelism()}};
}

// The kernel's stage clocks (--stage-clocks): ticks and each stage's share of the launches'.
nlohmann::ordered_json stageTicksJson(const DeviceReport& g) {
    std::uint64_t launches = 0;
    for (const DeviceReport::StageTicks& s : g.stageTicks) if (s.name == "launches") launches = s.ticks;
    nlohmann::ordered_json j;
    for (const DeviceReport::StageTicks& s : g.stageTicks)
        j[jsonKey(s.name)] = {{"ticks", s.ticks}, {"share", launches ? double(s.ticks) / double(launches) : 0.0}};
    return j;
}

nlohmann::ordered_json gpuJson(const DeviceReport& g) {
    nlohmann::ordered_json dispatches = nlohmann::ordered_json::array();
    for (const DeviceReport::Dispatch& d : g.dispatchTimes) dispatches.push_back({{"name", d.name}, {"gpu_ms", d.gpuMs}});
    nlohmann::ordered_json j = {{"device", g.device},
            {"driver", g.driver},
            {"workgroup_size", g.workgroupSize},
            {"subgroup_size", g.subgroupSize},
            {"ray_groups", g.rayGroups},
            {"leaf_rule", {{"ray_limit", g.rayLimit}, {"tri_limit", g.triLimit}, {"leaf_balance", g.leafBalance}}},
            {"packets", {{"count", g.packets}, {"flush", g.packetFlush}}},
            {"dispatches", g.dispatches},
            {"dispatch_times", dispatches},
            {"work_items_run", g.workItemsRun},
            {"work_items_empty", g.workItemsEmpty},
            {"work_item_slices", g.workItemSlices},
            {"rays_finished", g.raysFinished},
            {"validation_errors", g.validationErrors}};
    if (!g.workPasses.empty()) j["work_items"] = workItemsJson(g);  // gpu (rayquery has no work items)
    if (!g.stageTicks.empty()) j["stage_ticks"] = stageTicksJson(g);
    return j;
}

double perSecond(std::uint64_t rays, double ms) { return ms > 0.0 ? double(rays) / (ms * 1e-3) : 0.0; }

// Each pass in frame order: the primary (its details are the top level's), then each secondary
// pass with its rays, time, rays per second, counters, memory and work plan.
nlohmann::ordered_json passesJson(const RenderedFrame& frame, double primaryMs) {
    nlohmann::ordered_json passes = nlohmann::ordered_json::array();
    passes.push_back({{"name", "primary"}, {"rays", frame.rayCount}, {"trace_ms", primaryMs},
                      {"rays_per_second", perSecond(frame.rayCount, primaryMs)}});
    if (!frame.passes) return passes;
    for (const PassOutput& t : *frame.passes) {
        const TraceOutput& r = t.output;
        const double ms = t.ms - r.timings.pipelineCompileMs;
        std::uint64_t hits = 0;
        for (const RayHit& h : r.hits) hits += h.hit();
        nlohmann::ordered_json p = {{"name", t.pass.name},
                                    {"kind", t.pass.kind == PassKind::Shadow ? "shadow" : "occlusion"},
                                    {"slots", r.hits.size()},
                                    {"rays", t.rays},
                                    {"rays_hit", hits},
                                    {"trace_ms", ms},
                                    {"rays_per_second", perSecond(t.rays, ms)},
                                    {"trace_phases", phasesJson(r.timings)},  // a batched pass's: summed
                                    {"counters", countersJson(r.counters)},
                                    {"memory_plan_bytes", memoryJson(r.plan)}};
        if (t.tracedIn != PassOutput::kTracedAlone) {  // passes traced together: the pass that carries the trace
            p["traced_in"] = (*frame.passes)[t.tracedIn].pass.name;
            p["traced_in_index"] = t.tracedIn + 1;  // in this array, after the primary pass
        }
        if (t.pass.kind == PassKind::Occlusion) {
            p["rays_per_hit"] = t.pass.raysPerHit;
            p["distance"] = t.pass.occlusionDistance;
        }
        p["work_plan"] = workJson(r.plan);
        if (r.gpu) p["gpu"] = gpuJson(*r.gpu);
        passes.push_back(p);
    }
    return passes;
}

nlohmann::ordered_json lightsJson(const RenderedFrame& frame) {
    nlohmann::ordered_json lights = nlohmann::ordered_json::array();
    for (const Light& l : frame.lights) {
        nlohmann::ordered_json j = {{"name", l.name}, {"type", toString(l.type)}, {"intensity", l.intensity},
                                    {"color", {l.color.r, l.color.g, l.color.b}}};
        if (l.type == LightType::Directional) j["direction"] = vec(l.direction);
        else j["position"] = vec(l.position);
        lights.push_back(j);
    }
    return lights;
}

// The trace's options as the frame ran them: the DACRT backends' resolved, or Embree's own.
nlohmann::ordered_json optionsJson(const RenderOptions& o) {
    const TraceOptions& trace = o.tracer.trace;
    if (trace.backend == Backend::Embree)
        return {{"robust", o.tracer.embree.robust}, {"build", toString(o.tracer.embree.build)},
                {"packets", o.tracer.embree.packets ? "4x4 rtcIntersect16" : "rtcIntersect1"}};
    const DacrtOptions dacrt = trace.dacrt.resolvedFor(trace.backend);
    // The gpu's leaf rule depends on its device (gpu.leaf_rule reports the one it ran): a limit
    // not given is null here.
    auto limit = [&](std::uint32_t given, std::uint32_t resolved) -> nlohmann::ordered_json {
        if (trace.backend != Backend::Gpu) return resolved;
        return given ? nlohmann::ordered_json(given) : nlohmann::ordered_json(nullptr);
    };
    return {{"ray_limit", limit(trace.dacrt.rayLimit, dacrt.rayLimit)}, {"tri_limit", limit(trace.dacrt.triLimit, dacrt.triLimit)},
            {"max_depth", trace.dacrt.maxDepth}, {"split", toString(trace.dacrt.split)},
            {"split_cost", toString(trace.dacrt.splitCost)},
            {"axis", toString(trace.axis)}, {"intersector", toString(trace.dacrt.intersector)},
            {"triangle_filter", toString(trace.dacrt.triangleFilter)},
            {"precision", toString(trace.dacrt.precision)},
            {"ray_grouping", toString(trace.dacrt.rayGrouping)},
            {"pass_tracing", toString(trace.dacrt.passTracing)},
            {"tight_boxes", trace.dacrt.tightBoxes},
            {"cull", toString(o.cull)},
            {"skip_backfaces", trace.skips.backFaces},
            {"skip_frustum", trace.skips.frustum},
            {"skip_uploads", trace.skips.uploads},
            {"skip_subscenes", trace.skips.subScenes},
            {"skip_passrays", trace.skips.passRays}};
}

}  // namespace

nlohmann::ordered_json renderStatsJson(const RenderOptions& o, const RenderedFrame& frame) {
    const Scene& scene = frame.scene;
    const Camera& camera = frame.camera;
    const TraceOutput& r = frame.result;
    const TraceOptions& trace = o.tracer.trace;
    nlohmann::ordered_json j;
    j["backend"] = toString(trace.backend);
    j["scene"] = o.scenePath;
    j["frame"] = frame.instant.frame ? nlohmann::ordered_json(*frame.instant.frame) : nlohmann::ordered_json(nullptr);
    j["time_s"] = frame.instant.time;
    j["animation"] = o.animationChoice.empty() ? std::string("(all)") : o.animationChoice;
    j["triangles"] = scene.triangleCount();
    j["triangles_dropped_degenerate"] = scene.degenerateTrianglesDropped;
    j["rays"] = frame.rayCount;
    j["width"] = o.width;
    j["height"] = o.height;
    j["regions"] = r.counters.regions;
    j["threads"] = r.counters.threads;
    const int axis = r.counters.divisionAxis;
    j["division_axis"] = axis < 0 ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(std::string(1, "xyz"[axis]));
    j["camera"] = {{"index", frame.cameraIndex}, {"projection", toString(camera.projection)}, {"eye", vec(camera.eye)},
                   {"forward", vec(camera.forward)}, {"up", vec(camera.up)}};
    if (camera.projection == Projection::Perspective) j["camera"]["yfov_degrees"] = glm::degrees(camera.yfovRadians);
    else j["camera"]["ymag"] = camera.ymag;
    if (scene.camera && !scene.camera->name.empty()) j["camera"]["name"] = scene.camera->name;
    j["options"] = optionsJson(o);
    nlohmann::ordered_json t;
    for (const auto& [name, ms] : frame.timingsMs) t[name] = ms;
    const nlohmann::ordered_json phases = phasesJson(r.timings);
    if (!phases.empty()) t["trace_phases"] = phases;
    if (!r.timings.step1RegionMs.empty()) t["step1_region"] = r.timings.step1RegionMs;
    nlohmann::ordered_json setup;  // evaluate_animation's phases
    for (const auto& [name, ms] : frame.scene.setupPhasesMs) setup[name] = ms;
    if (!setup.empty()) t["setup_phases"] = setup;
    j["timings_ms"] = t;
    j["memory_plan_bytes"] = memoryJson(r.plan);
    // What the plan is measured against: the whole process, so its peak holds the parsed file,
    // the scene and every earlier frame and pass as well as this frame's buffers.
    nlohmann::ordered_json sceneBytes;
    std::uint64_t sceneTotal = 0;
    for (const auto& [name, bytes] : sceneArrayBytes(scene)) {
        sceneBytes[jsonKey(name)] = bytes;
        sceneTotal += bytes;
    }
    sceneBytes["total"] = sceneTotal;
    j["memory_scene_bytes"] = sceneBytes;  // held beside every plan, counted in none
    if (const std::optional<ResidentMemory> m = residentMemory())
        j["memory_measured_bytes"] = {{"resident", m->current}, {"peak_resident", m->peak}};
    nlohmann::ordered_json dropped = nlohmann::ordered_json::array();
    dropped.push_back({{"name", "degenerate triangles dropped at load"},
                       {"count", frame.scene.degenerateTrianglesDropped},
                       {"why", "no area: never hit"}});
    j["work_plan"] = workJson(r.plan, dropped);
    j["counters"] = countersJson(r.counters);
    std::uint64_t hits = 0;
    for (const RayHit& h : r.hits) hits += h.hit();
    j["hits"] = hits;
    if (r.gpu) j["gpu"] = gpuJson(*r.gpu);
    double primaryMs = 0.0;
    for (const auto& [name, ms] : frame.timingsMs)
        if (name == "trace") primaryMs = ms;
    j["lights"] = lightsJson(frame);
    j["shading"] = {{"model", frame.lights.empty() ? "headlight" : "lambert with shadows"},
                    {"exposure", frame.exposure},
                    {"occlusion_rays_per_hit", o.passes.occlusionSamples}};
    j["passes"] = passesJson(frame, primaryMs);
    return j;
}

}  // namespace dacrt
