#include "peers/rayquery_tracer.hpp"

#include <algorithm>

#include "core/timing.hpp"
#include "peers/acceleration_structure.hpp"
#include "gpu/buffer.hpp"
#include "gpu/dispatch_recorder.hpp"

namespace dacrt {
namespace {

constexpr std::uint32_t kRaysPerWorkgroup = 64;  // local_size_x of shaders/rayquery.comp

// shaders/rayquery.comp's push constants.
struct RayQueryPush {
    std::uint32_t rayCount = 0;
    std::uint32_t firstRay = 0;
    std::uint32_t cullBackFaces = 0;
    std::uint32_t anyHit = 0;
};
static_assert(sizeof(RayQueryPush) == 4 * sizeof(std::uint32_t), "the push range PipelineCache::rayQuery declares");

gpu::AccelerationBuild accelerationBuildOf(RayQueryBuild b) {
    switch (b) {
        case RayQueryBuild::Dynamic: return gpu::AccelerationBuild::FastBuild;
        case RayQueryBuild::Refit: return gpu::AccelerationBuild::Updatable;
        case RayQueryBuild::Static: return gpu::AccelerationBuild::FastTrace;
    }
    return gpu::AccelerationBuild::FastBuild;
}

}  // namespace

struct RayQueryScene::Impl {
    gpu::Context& context;
    gpu::PipelineCache& pipelines;
    const std::vector<Triangle>& triangles;
    RayQueryBuild build;
    gpu::Buffer vertices;
    gpu::Faces faces;  // before structure, which is made with it
    gpu::TriangleAccelerationStructure structure;
    std::unique_ptr<gpu::Buffer> rays, hits;
    bool built = false;

    Impl(gpu::Context& c, gpu::PipelineCache& p, const std::vector<Triangle>& t, RayQueryBuild b)
        : context(c), pipelines(p), triangles(t), build(b),
          vertices(c, t.size() * sizeof(Triangle), "rayquery vertices", gpu::BufferUse::AccelerationInput),
          faces(facesOf(t)), structure(c, vertices, t.size(), accelerationBuildOf(b), faces) {}

    // With single-sided triangles the shader decides per candidate, from the facing the
    // instance reports (so it must not disable facing).
    static gpu::Faces facesOf(const std::vector<Triangle>& t) {
        return singleSidedTriangles(t) ? gpu::Faces::FrontOnly : gpu::Faces::Both;
    }
};

RayQueryScene::RayQueryScene(gpu::Context& context, gpu::PipelineCache& pipelines, const std::vector<Triangle>& triangles,
                             RayQueryBuild build) {
    gpu::requireRayQuery(context.info());
    impl_ = std::make_unique<Impl>(context, pipelines, triangles, build);
}

RayQueryScene::~RayQueryScene() = default;

TraceResult RayQueryScene::trace(const std::vector<Ray>& rays, HitQuery query) {
    Impl& m = *impl_;
    TraceResult result;
    result.gpu = GpuReport{};
    result.gpu->device = m.context.info().name;
    result.gpu->driver = m.context.info().driver;
    result.regions = 1;

    auto start = Clock::now();
    const bool rebuild = !m.built || m.build == RayQueryBuild::Dynamic;
    const bool refit = m.built && m.build == RayQueryBuild::Refit;
    if (rebuild || refit) m.vertices.upload(m.triangles.data(), m.triangles.size() * sizeof(Triangle));
    if (!m.rays || m.rays->size() < rays.size() * sizeof(Ray)) {
        m.rays = std::make_unique<gpu::Buffer>(m.context, rays.size() * sizeof(Ray), "rayquery rays");
        m.hits = std::make_unique<gpu::Buffer>(m.context, rays.size() * sizeof(Hit), "rayquery hits");
    }
    m.rays->upload(rays.data(), rays.size() * sizeof(Ray));
    result.phases.upload = msSince(start);

    gpu::ComputePipeline& pipeline = m.pipelines.rayQuery();
    pipeline.bind({m.rays.get(), m.hits.get(), nullptr, &m.vertices});
    pipeline.bindAccelerationStructure(2, m.structure.topLevel());

    // lavapipe compiles a pipeline at its first dispatch (seconds without Mesa's shader cache),
    // so the first frame runs the shader once over no rays, after the structure it binds is
    // built and before the timed trace: the compile is reported as the pipeline's.
    const bool prime = !m.pipelines.rayQueryPrimed();
    start = Clock::now();
    const std::uint32_t perDispatch = m.context.info().maxComputeWorkGroupCountX;
    const std::uint32_t groups = std::uint32_t((rays.size() + kRaysPerWorkgroup - 1) / kRaysPerWorkgroup);
    std::vector<std::pair<std::string, double>> timings;
    auto runSteps = [&](bool buildSteps, bool traceSteps) {
        gpu::DispatchRecorder recorder(m.context, 1 + (groups + perDispatch - 1) / perDispatch);
        if (buildSteps)
            recorder.buildAccelerationStructures(refit ? "refit" : "build",
                                                 [&](VkCommandBuffer commands) { m.structure.record(commands, refit); });
        for (std::uint32_t done = 0; traceSteps && done < groups; done += perDispatch) {
            const RayQueryPush push{std::uint32_t(rays.size()), done * kRaysPerWorkgroup,
                                    m.faces == gpu::Faces::FrontOnly ? 1u : 0u, query == HitQuery::Any ? 1u : 0u};
            recorder.dispatch("trace", pipeline, std::min(perDispatch, groups - done), &push);
        }
        recorder.submitAndWait();
        for (const auto& t : recorder.timingsMs()) timings.push_back(t);
    };
    double compileMs = 0.0;
    if (prime) {
        if (rebuild || refit) runSteps(true, false);
        const auto compileStart = Clock::now();
        gpu::DispatchRecorder recorder(m.context, 1);
        const RayQueryPush noRays{};
        recorder.dispatch("prime", pipeline, 1, &noRays);
        recorder.submitAndWait();
        m.pipelines.markRayQueryPrimed();
        compileMs = msSince(compileStart);
        runSteps(false, true);
    } else {
        runSteps(rebuild || refit, true);
    }
    m.built = true;
    result.gpu->dispatchMs = timings;
    result.gpu->dispatches = std::uint32_t(timings.size());
    double buildMs = 0.0;
    for (const auto& [name, ms] : timings)
        if (name != "trace") buildMs += ms;
    if (rebuild || refit) (refit ? result.phases.refit : result.phases.build) = buildMs;
    if (prime) result.phases.pipelineCompile = compileMs;
    result.phases.dispatch = msSince(start) - compileMs;

    start = Clock::now();
    result.hits.resize(rays.size());
    m.hits->download(result.hits.data(), rays.size() * sizeof(Hit));
    result.phases.readback = msSince(start);
    result.memory.add("device: rayquery vertices", m.vertices.size());
    result.memory.add("device: acceleration structure and scratch", m.structure.bytes());
    result.memory.add("device: rays", m.rays->size());
    result.memory.add("device: hits", m.hits->size());
    result.gpu->validationErrors = m.context.validationErrors();
    return result;
}

std::optional<TraceResult> stoppedAtPlan(const FrameGeometry& geometry, const PlanHook& onPlan) {
    if (!onPlan) return std::nullopt;
    TraceResult planned;
    planned.memory.add("device: rayquery vertices", geometry.triangles->size() * sizeof(Triangle));
    planned.memory.add("device: rays", geometry.rays->size() * sizeof(Ray));
    planned.memory.add("device: hits", geometry.rays->size() * sizeof(Hit));
    if (onPlan(planned.memory)) return std::nullopt;
    return planned;
}

TraceResult traceRayQuery(const FrameGeometry& geometry, gpu::Context& context, gpu::PipelineCache& pipelines,
                          const PlanHook& onPlan) {
    if (std::optional<TraceResult> planned = stoppedAtPlan(geometry, onPlan)) return *planned;
    const auto start = Clock::now();
    RayQueryScene scene(context, pipelines, *geometry.triangles, RayQueryBuild::Dynamic);
    const double allocateMs = msSince(start);
    TraceResult result = scene.trace(*geometry.rays, geometry.query);
    result.phases.allocate = allocateMs;
    return result;
}

}  // namespace dacrt
