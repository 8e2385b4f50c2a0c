#include "library/backend_dispatcher.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <optional>
#include <ostream>
#include <thread>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"
#include "core/timing.hpp"
#include "cpu/backend_options.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/image_bands.hpp"
#include "cpu/pass_cull.hpp"
#include "cpu/triangle_skips.hpp"
#include "gpu/device_defaults.hpp"
#include "library/triangle_batches.hpp"

namespace dacrt {

namespace {

// How many workers trace a cpu pass's groups side by side (traceGroupsSideBySide; 1: none).
// The groups are independent frames: with more than one worker, each takes whole groups,
// sequential DACRTs with no division, binning or transfer round between them, where the
// parallel scheme would divide every group again and wait at each of its rounds. Regions asked
// for (--regions) keep the parallel scheme.
std::size_t sideBySideWorkers(const BackendRequest& request, std::size_t workers) {
    return request.trace.backend == Backend::Cpu && request.trace.regions == 0 ? workers : 1;
}

// What making a pass's rays on the host allocates, from the counts: its rays and their slots
// (at most: a miss sends none) and its hit per slot. Throws where the pass has too many slots.
MemoryPlan makingPlan(const SecondaryPass& pass, std::uint64_t primaryRays) {
    const std::uint64_t slots = secondarySlots(pass, primaryRays);
    MemoryPlan making;
    making.add("secondary rays and their slots (at most)", slots * (sizeof(Ray) + sizeof(std::uint32_t)));
    making.add("hits per slot", slots * sizeof(Hit));
    return making;
}

// Whether any of `backends` opens the Vulkan device.
bool usesVulkan(const std::vector<Backend>& backends) {
    return std::any_of(backends.begin(), backends.end(), runsOnVulkan);
}

// Whether a gpu pass goes the host's way although the primary hits are on the device: its rays
// made on the host (the device's, bit for bit) for the pass cull, where the cull may drop
// triangles. The pass makes at most raysPerHit rays per surface the primary rays hit.
bool culledOnTheHost(const SecondaryPass& pass, const std::vector<Hit>& primaryHits, const std::vector<Triangle>& triangles,
                     const SkipSwitches& switches) {
    const std::uint64_t surfaces = surfacesSendingRays(primaryHits);
    // A light's shadow rays share its direction or end at it, and the back-face tests drop
    // single-sided triangles only (glTF's default: the search stops at the first one).
    const bool sharedFacing = pass.kind == shared::kPassShadow &&
                              std::any_of(triangles.begin(), triangles.end(), [](const Triangle& t) { return t.cullBackFace != 0u; });
    return passCullMayDrop(surfaces * pass.raysPerHit, triangles.size(), sharedFacing, switches);
}

// Whether the request leaves the gpu's regions and ray groups to a device that takes a CPU's
// defaults (lavapipe): neither asked for.
bool shapeLeftToACpuDevice(const BackendRequest& request, const gpu::DeviceInfo& device) {
    return request.trace.regions == 0 && request.gpuTuning.rayGroups == 0 &&
           gpu::takesCpuDefaults(device, request.gpuTuning.profile);
}

// The request as one region of `groups` ray groups (at most kMostDefaultRayGroups).
BackendRequest asOneRegion(const BackendRequest& request, std::size_t groups) {
    BackendRequest one = request;
    one.trace.regions = 1;
    one.gpuTuning.rayGroups = std::uint32_t(std::min<std::size_t>(groups, gpu::kMostDefaultRayGroups));
    return one;
}

// A gpu pass's request on a device that takes a CPU's defaults (lavapipe), where neither the
// regions nor the ray groups were asked for: one region, its rays in the cpu backend's
// batches, each batch a ray group (a work item of Step 1 with the whole scene's triangles).
// Secondary rays cross every region, so regions would pass each ray through transfer rounds;
// the groups are the cpu's side-by-side batches on the device's threads (docs/gpu.md, "A
// pass's rays as one region's ray groups on a CPU device"). Elsewhere the request as given.
BackendRequest gpuPassRequest(const BackendRequest& request, const gpu::DeviceInfo& device, std::size_t rays,
                              std::size_t triangles) {
    if (!shapeLeftToACpuDevice(request, device)) return request;
    const std::size_t batches =
        rayBatches(rays, passBatchRays(triangles), gpu::defaultGpuRegions(device, request.gpuTuning.profile)).size() - 1;
    return asOneRegion(request, batches);
}

// A gpu primary frame's request on a device that takes a CPU's defaults, where neither the
// regions nor the ray groups were asked for (nor the sub-scenes, --no-skip subscenes) and the
// cpu backend would cut the image into at least two bands a core (imageBandCount: a scene of few
// triangles for its rays, as the room): one region with as many ray groups as bands (the
// kernel's even groups of its rays), so that no ray waits for a transfer round. Where the
// bands are fewer, the regions stay: a work item's own pass over every triangle costs the
// kernel more than the rounds save (docs/gpu.md, "Leaf groups and image bands").
BackendRequest gpuPrimaryRequest(const BackendRequest& request, const gpu::DeviceInfo& device,
                                 const FrameGeometry& geometry) {
    if (!shapeLeftToACpuDevice(request, device) || !request.trace.skips.subScenes) return request;
    const unsigned cores = gpu::defaultGpuRegions(device, request.gpuTuning.profile);
    const std::size_t bands = imageBandCount(geometry, cores);
    return bands < 2 * std::size_t(cores) ? request : asOneRegion(request, bands);
}

}  // namespace

void checkBackendRequest(const BackendRequest& r) {
    checkRequestedOptions({r.trace, r.gpuTuning.workgroupSize, r.gpuTuning.rayGroups, r.embree.robust, r.embree.packets,
                           r.gpuTuning.profile, r.gpuTuning.stageClocks, r.gpuTuning.leafBalance});
}

void checkDeviceChoice(const DeviceChoice& devices, const std::vector<Backend>& backends) {
    if (usesVulkan(backends)) return;
    if (!devices.device.empty()) throw InputError("--device chooses the Vulkan device of the gpu and rayquery backends; neither runs here");
    if (devices.validate) throw InputError("--validate runs the gpu and rayquery backends under the Vulkan validation layers; neither runs here");
}

BackendDispatcher::BackendDispatcher(const DeviceChoice& devices, const std::vector<Backend>& backends)
    : devices_(devices) {
    if (usesVulkan(backends)) {
        gpu_ = std::make_unique<gpu::Context>(gpu::ContextOptions{devices.device, devices.validate});
        pipelines_ = std::make_unique<gpu::PipelineCache>(*gpu_);
        resident_ = std::make_unique<gpu::ResidentTriangles>();
        arena_ = std::make_unique<gpu::BufferArena>();
    }
}

BackendDispatcher::~BackendDispatcher() = default;

void BackendDispatcher::releaseKept() {
    passSource_.reset();  // first: it holds buffers of the arena
    peers_.clear();
    grouping_ = GroupingBuffers{};
    if (resident_) resident_ = std::make_unique<gpu::ResidentTriangles>();
    if (arena_) arena_ = std::make_unique<gpu::BufferArena>();
}

unsigned BackendDispatcher::threadsOf(const TraceOptions& options) {
    if (options.backend == Backend::CpuSeq) return 1;
    return options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
}

ThreadPool& BackendDispatcher::pool(unsigned threads) {
    std::unique_ptr<ThreadPool>& p = pools_[threads];
    if (!p) p = std::make_unique<ThreadPool>(threads);
    return *p;
}

TraceResult BackendDispatcher::trace(const FrameGeometry& geometry, const BackendRequest& request,
                                     const PlanHook& onPlan, const ProgressHook& onProgress) {
    checkBackendRequest(request);
    passSource_.reset();  // a later traceSecondary must not find an earlier frame's buffers
    ThreadPool& threadPool = pool(threadsOf(request.trace));
    if (isPeer(request.trace.backend)) return traceOnBackend(geometry, request, onPlan, onProgress, PeerFrame::New);

    // dacrt's backends trace the triangles no skip dropped; the plan starts with the skips.
    const auto start = Clock::now();
    const TriangleSkips skips = skipTriangles(geometry, request.trace.skips, threadPool);
    MemoryPlan skipPlan;
    planSkips(geometry, request.trace.skips, skips, skipPlan);
    return traceAfterSkips(geometry, skips, skipPlan, msSince(start), request, onPlan, onProgress);
}

TraceResult BackendDispatcher::traceAfterSkips(const FrameGeometry& geometry, const TriangleSkips& skips,
                                               const MemoryPlan& skipPlan, double skipMs, const BackendRequest& request,
                                               const PlanHook& onPlan, const ProgressHook& onProgress) {
    auto withSkipLines = [&](TraceResult r) {
        r.memory.work.insert(r.memory.work.begin(), skipPlan.work.begin(), skipPlan.work.end());
        r.phases.skips = skipMs;
        return r;
    };
    const PlanHook planWithSkips = withWorkLines(onPlan, skipPlan.work, true);
    if (skips.applied && skips.traced.empty()) {
        // No triangle can be hit: every ray misses, with nothing to divide or upload.
        TraceResult r;
        r.threads = pool(threadsOf(request.trace)).size();
        r.memory.add("hits", std::uint64_t(geometry.rays->size()) * sizeof(Hit));
        if (!planWithSkips || planWithSkips(r.memory)) {
            r.hits.reserve(geometry.rays->size());
            for (const Ray& ray : *geometry.rays) r.hits.push_back(missHit(ray));
            r.counters.raysCulled = geometry.rays->size();
        }
        return withSkipLines(std::move(r));
    }
    const FrameGeometry traced = withSkips(geometry, skips);
    return withSkipLines(traceOnBackend(traced, request, planWithSkips, onProgress, PeerFrame::New));
}

TraceResult BackendDispatcher::traceOnBackend(const FrameGeometry& geometry, const BackendRequest& request,
                                              const PlanHook& onPlan, const ProgressHook& onProgress,
                                              PeerFrame frame) {
    const unsigned threads = threadsOf(request.trace);
    ThreadPool& threadPool = pool(threads);
    switch (request.trace.backend) {
        case Backend::Gpu: {
            if (!gpu_) throw InternalError("the gpu backend was asked for a trace without a device being opened");
            // A closest-hit trace starts a frame (a pass culled on the host traces any hits): the
            // last frame's buffers kept for its passes go back to the arena for this one. A frame
            // beyond the device's memory runs in triangle batches, each a frame of the arena's,
            // none kept for the passes (they then make their rays on the host).
            const bool closest = geometry.query == HitQuery::Closest;
            if (closest && request.keepForPasses) passSource_.reset();
            bool whole = true;
            const BackendRequest asked = closest ? gpuPrimaryRequest(request, gpu_->info(), geometry) : request;
            const auto traceOne = [&](const FrameGeometry& g, const std::vector<WorkLine>& planLines) {
                if (closest) arena_->startFrame();
                GpuTracer tracer(*gpu_, threadPool, asked.trace, asked.gpuTuning, pipelines_.get(), resident_.get(),
                                 arena_.get());
                const bool keep = whole && request.keepForPasses && closest;
                whole = false;
                return tracer.trace(g, withWorkLines(onPlan, planLines, false), keep ? &passSource_ : nullptr);
            };
            return traceInTriangleBatches(geometry, traceOne);
        }
        case Backend::Embree: {
            // Embree allocates its BVH itself: its plan bounds it from the triangle count.
            EmbreeOptions embree = request.embree;
            embree.threads = threads;
            return peers_.traceEmbree(geometry, embree, threadPool, onPlan, frame);
        }
        case Backend::RayQuery:
            if (!gpu_) throw InternalError("the rayquery backend was asked for a trace without a device being opened");
            return peers_.traceRayQuery(geometry, request.rayQueryBuild, *gpu_, *pipelines_, onPlan, frame);
        case Backend::Brute:
        case Backend::CpuSeq:
        case Backend::Cpu: return traceCpu(geometry, request.trace, threadPool, onPlan, onProgress);
    }
    throw InternalError("unknown backend");
}

BackendDispatcher::PassTrace BackendDispatcher::traceSecondary(const FrameGeometry& primary,
                                                               const std::vector<Hit>& primaryHits,
                                                               const SecondaryPass& pass, const BackendRequest& request,
                                                               const PlanHook& onPlan) {
    checkBackendRequest(request);
    ThreadPool& threadPool = pool(threadsOf(request.trace));
    // On gpu the rays are made where the primary pass left its hits, unless the pass cull may
    // drop triangles, or the device takes a CPU's defaults (lavapipe): the host makes them then,
    // as for the other backends. On a CPU device the host's division and square root are
    // instructions where the kernel builds them from integer operations (exact_math.glsl), for
    // the same bits (docs/gpu.md, "Rays made on the host for a CPU device"). A frame the skips
    // left empty (no triangle: every primary ray misses) kept nothing on the device.
    if (request.trace.backend == Backend::Gpu && passSource_ &&
        !gpu::takesCpuDefaults(gpu_->info(), request.gpuTuning.profile) &&
        !culledOnTheHost(pass, primaryHits, *primary.triangles, request.trace.skips))
        return traceMadeOnDevice(primary, pass, request, onPlan);
    PassTrace out;
    const bool cpuDacrt = request.trace.backend == Backend::Cpu || request.trace.backend == Backend::CpuSeq;
    BackendRequest passRequest = request;
    if (cpuDacrt) passRequest.trace.dacrt = passDacrtOptions(request.trace.dacrt);
    // The slot arrays are allocated before the tracer plans: checked first, as its plan is.
    const std::uint64_t slots = secondarySlots(pass, primary.rays->size());
    MemoryPlan making = makingPlan(pass, primary.rays->size());
    const RayGrouping grouping = cpuDacrt ? request.trace.dacrt.rayGrouping : RayGrouping::Slots;
    const bool byOctant = grouping == RayGrouping::Octant || grouping == RayGrouping::OctantCalls;
    const PassRayCounts counts = passRayCounts(pass, primaryHits, threadPool);
    std::optional<SecondaryRays> madeAlready;  // a made pass's rays that go on from their array
    double makeMs = 0.0;
    if (tracesMadeSideBySide(pass, counts.total(), primary.triangles->size(), passRequest.trace, threadPool.size())) {
        MadePass made = traceMadeSideBySide(primary, primaryHits, pass, counts, passRequest.trace, threadPool,
                                            madeGroups_, passCull_, onPlan);
        if (!made.unmade) {
            out.result = std::move(made.result);
            out.rays = made.rays;
            return out;
        }
        madeAlready = std::move(made.unmade);
        makeMs = made.makeMs;
    }
    if (byOctant)  // kept for the next pass
        making.add("rays and slots grouped by octant (at most)", slots * (sizeof(Ray) + sizeof(std::uint32_t)));
    if (grouping == RayGrouping::OctantCalls || grouping == RayGrouping::Batches)
        making.add("the rays of the groups being traced (at most)", slots * sizeof(Ray));  // one, or one a worker
    if (onPlan && !onPlan(making)) return out;
    const auto start = Clock::now();
    SecondaryRays rays = madeAlready ? std::move(*madeAlready)
                                     : makeSecondaryRays(pass, *primary.rays, primaryHits, *primary.triangles, counts, threadPool);
    if (!madeAlready) makeMs = msSince(start);
    out.rays = rays.rays.size();
    if (rays.rays.empty()) {  // no surface sends a ray: nothing to plan or trace
        out.result.hits = hitsPerSlot(rays, {}, &threadPool);
    } else {
        std::vector<std::size_t> groups = {0, rays.rays.size()};  // one trace of every ray
        std::optional<double> groupMs;
        if (byOctant) {
            const auto groupStart = Clock::now();
            const OctantStarts octants = groupByOctant(rays, grouping_, threadPool);
            groupMs = msSince(groupStart);
            if (grouping == RayGrouping::OctantCalls) groups.assign(octants.begin(), octants.end());
        } else if (grouping == RayGrouping::Batches) {
            groups = rayBatches(rays.rays.size(), passBatchRays(primary.triangles->size()),
                                sideBySideWorkers(request, threadPool.size()));
        }
        if (request.trace.backend == Backend::Gpu && gpu_)
            passRequest = gpuPassRequest(request, gpu_->info(), rays.rays.size(), primary.triangles->size());
        out.result = groups.size() > 2 ? traceGroups(primary, rays.rays, groups, passRequest, onPlan)
                                       : tracePassRays(primary, rays.rays, passRequest, onPlan);
        if (out.result.hits.empty()) return out;  // stopped at the plan
        out.result.hits = hitsPerSlot(rays, out.result.hits, &threadPool);
        out.result.phases.groupRays = groupMs;
    }
    out.result.phases.makeRays = makeMs;
    return out;
}

std::uint64_t BackendDispatcher::slotsTogether(const std::vector<SecondaryPass>& passes, std::uint64_t primaryRays) {
    std::uint64_t slots = 0;  // each pass's at most kMaxSecondarySlots: no overflow for kMostPassesTogether
    for (const SecondaryPass& pass : passes) slots += secondarySlots(pass, primaryRays);
    return slots;
}

std::vector<BackendDispatcher::PassTrace> BackendDispatcher::traceSecondaryTogether(
    const FrameGeometry& primary, const std::vector<Hit>& primaryHits, const std::vector<SecondaryPass>& passes,
    const BackendRequest& request, const PlanHook& onPlan) {
    checkBackendRequest(request);
    if (passes.empty() || passes.size() > kMostPassesTogether)
        throw InternalError(std::to_string(passes.size()) + " passes to trace together");
    ThreadPool& threadPool = pool(threadsOf(request.trace));
    // Each pass's making plan (as traceSecondary's), every one checked before anything is made,
    // then the merged copy of their rays.
    std::vector<MemoryPlan> makings;
    const std::uint64_t slots = slotsTogether(passes, primary.rays->size());
    if (slots > kMaxSecondarySlots)
        throw InputError("passes traced together: " + std::to_string(primary.rays->size()) +
                         " pixels make more than the " + std::to_string(kMaxSecondarySlots) +
                         " rays one trace can hold (32-bit ids); lower --size or --ao, or --pass-tracing apart");
    for (const SecondaryPass& pass : passes) makings.push_back(makingPlan(pass, primary.rays->size()));
    MemoryPlan merging;
    merging.add("the passes' rays merged pixel by pixel, with their pass and slot (at most)",
                slots * (sizeof(Ray) + sizeof(std::uint32_t) + sizeof(std::uint16_t)));
    if (request.trace.dacrt.rayGrouping == RayGrouping::Batches)
        merging.add("the rays of the groups being traced (at most)", slots * sizeof(Ray));  // one, or one a worker
    merging.addWork("passes traced together", passes.size(),
                    "their rays merged pixel by pixel into the same traces, which divide the triangles once");
    for (const MemoryPlan& plan : makings)
        if (onPlan && !onPlan(plan)) return {};
    if (onPlan && !onPlan(merging)) return {};
    const auto start = Clock::now();
    std::vector<SecondaryRays> made;
    made.reserve(passes.size());
    std::size_t total = 0;
    for (const SecondaryPass& pass : passes) {
        made.push_back(makeSecondaryRays(pass, *primary.rays, primaryHits, *primary.triangles, threadPool));
        total += made.back().rays.size();
    }
    // Pixel by pixel: a pixel's rays of every pass start at its surface and lie together in
    // the batches (equal runs of the merged rays).
    std::vector<Ray> rays;
    std::vector<std::uint32_t> slotOf;
    std::vector<std::uint16_t> passOf;
    reserveMapped(rays, total);
    reserveMapped(slotOf, total);
    reserveMapped(passOf, total);
    std::vector<std::size_t> next(passes.size(), 0);
    constexpr std::uint64_t kNoPixel = ~std::uint64_t(0);
    auto pixelOf = [&](std::size_t p) {
        return next[p] < made[p].slots.size() ? std::uint64_t(made[p].slots[next[p]] / passes[p].raysPerHit) : kNoPixel;
    };
    while (rays.size() < total) {
        std::size_t first = 0;
        for (std::size_t p = 1; p < passes.size(); ++p)
            if (pixelOf(p) < pixelOf(first)) first = p;
        const std::uint64_t pixel = pixelOf(first);
        for (std::size_t p = first; p < passes.size(); ++p)
            for (; pixelOf(p) == pixel; ++next[p]) {
                rays.push_back(made[p].rays[next[p]]);
                slotOf.push_back(made[p].slots[next[p]]);
                passOf.push_back(std::uint16_t(p));
            }
    }
    std::vector<PassTrace> out(passes.size());
    std::vector<std::uint64_t> slotCount(passes.size());
    for (std::size_t p = 0; p < passes.size(); ++p) {  // each pass's own copy no longer needed
        out[p].rays = made[p].rays.size();
        slotCount[p] = made[p].slotCount;
    }
    made.clear();
    const double makeMs = msSince(start);
    TraceResult traced;
    if (!rays.empty()) {
        const std::vector<std::size_t> groups =
            request.trace.dacrt.rayGrouping == RayGrouping::Batches
                ? rayBatches(rays.size(), passBatchRays(primary.triangles->size()),
                             sideBySideWorkers(request, threadPool.size()))
                : std::vector<std::size_t>{0, rays.size()};
        traced = groups.size() > 2 ? traceGroups(primary, rays, groups, request, onPlan)
                                   : tracePassRays(primary, rays, request, onPlan);
        if (traced.hits.empty()) return {};  // stopped at the plan
    }
    if (traced.hits.size() != rays.size())
        throw InternalError("passes traced together: " + std::to_string(traced.hits.size()) + " hits for " +
                            std::to_string(rays.size()) + " rays");
    std::vector<std::vector<Hit>> hitsOfPass(passes.size());
    for (std::size_t p = 0; p < passes.size(); ++p) hitsOfPass[p] = notTracedSlots(slotCount[p], &threadPool);
    scatterToSlots(hitsOfPass, slotOf.data(), passOf.data(), traced.hits.data(), traced.hits.size(), &threadPool);
    out.back().result = std::move(traced);  // the shared trace's plan, phases and counters
    for (std::size_t p = 0; p < passes.size(); ++p) out[p].result.hits = std::move(hitsOfPass[p]);
    out.back().result.phases.makeRays = makeMs;
    std::vector<WorkLine>& work = out.back().result.memory.work;
    work.insert(work.begin(), merging.work.begin(), merging.work.end());
    return out;
}

namespace {

// One group's trace appended to the pass's: its hits after the earlier groups', its counters
// summed, the transfer rounds of the same name together (the division and plan stay the first
// group's).
void addGroup(TraceResult& whole, TraceResult&& part, std::size_t passRays) {
    if (whole.hits.empty()) {
        whole = std::move(part);
        return;
    }
    if (whole.hits.capacity() < passRays) reserveMapped(whole.hits, passRays);  // every group's hits at once
    whole.hits.insert(whole.hits.end(), part.hits.begin(), part.hits.end());
    whole.counters.addTrace(part.counters);
    whole.phases.add(part.phases);
}

}  // namespace

TraceResult BackendDispatcher::tracePassRays(const FrameGeometry& primary, const std::vector<Ray>& rays,
                                             const BackendRequest& request, const PlanHook& onPlan) {
    const FrameGeometry g = passFrame(primary, rays, &pool(threadsOf(request.trace)));
    return isPeer(request.trace.backend) ? traceOnBackend(g, request, onPlan, {}, PeerFrame::SamePass)
                                         : traceCulled(g, request, onPlan);
}

TraceResult BackendDispatcher::traceGroupsSideBySide(const FrameGeometry& primary, const std::vector<Ray>& rays,
                                                     const std::vector<std::size_t>& groups,
                                                     const std::vector<std::size_t>& live,
                                                     const BackendRequest& request, const PlanHook& onPlan,
                                                     const MemoryPlan& cullPlan, double cullMs) {
    ThreadPool& threadPool = pool(threadsOf(request.trace));
    const std::size_t largest = *std::max_element(live.begin(), live.end(), [&](std::size_t a, std::size_t b) {
        return groups[a + 1] - groups[a] < groups[b + 1] - groups[b];
    });
    const std::size_t workers = std::min<std::size_t>(threadPool.size(), live.size());
    workerGroups_.resize(threadPool.size());
    auto groupOf = [&](std::size_t k, std::vector<Ray>& into) {
        reserveMapped(into, groups[k + 1] - groups[k]);
        into.assign(rays.begin() + std::ptrdiff_t(groups[k]), rays.begin() + std::ptrdiff_t(groups[k + 1]));
        return withSkips(passFrame(primary, into), passCull_.skips);
    };
    // The plan: the largest group's sequential plan once a worker (a bound: the triangles' own
    // arrays are shared), after the pass cull's lines.
    const std::vector<WorkLine> lines{
        {"ray groups side by side", live.size(),
         "each a sequential DACRT on one of " + std::to_string(workers) + " workers: no division or transfer rounds"}};
    MemoryPlan plan;
    plan.work = cullPlan.work;
    traceSequential(groupOf(largest, workerGroups_[0]), request.trace.dacrt, [&](const MemoryPlan& one) {
        for (const auto& [name, bytes] : one.buffers)
            plan.add(name + " (x" + std::to_string(workers) + " workers, at most)", bytes * workers);
        plan.work.insert(plan.work.end(), one.work.begin(), one.work.end());
        return false;
    });
    plan.work.insert(plan.work.end(), lines.begin(), lines.end());
    if (onPlan && !onPlan(plan)) return {};
    const auto start = Clock::now();
    std::vector<TraceResult> parts(groups.size());
    threadPool.parallelForRethrowing(live.size(), [&](std::size_t i, unsigned worker) {
        parts[live[i]] = traceSequential(groupOf(live[i], workerGroups_[worker]), request.trace.dacrt);
    });
    const double traceMs = msSince(start);
    TraceResult whole;
    for (std::size_t k : live) addGroup(whole, std::move(parts[k]), rays.size());
    whole.memory = std::move(plan);
    whole.threads = unsigned(workers);
    whole.regions = 1;
    whole.phases = PhaseTimes{};
    whole.phases.skips = cullMs;
    whole.phases.step1 = traceMs;
    return whole;
}

TraceResult BackendDispatcher::traceGroups(const FrameGeometry& primary, const std::vector<Ray>& rays,
                                           const std::vector<std::size_t>& groups, const BackendRequest& request,
                                           const PlanHook& onPlan) {
    // The pass cull once, over every ray: each group's own would survey its rays again.
    // The pass's geometry only where the cull tests something: its survey of the rays is a
    // pass over every one of them (3 ms for the room's 1.2 million occlusion rays).
    const auto start = Clock::now();
    ThreadPool& threadPool = pool(threadsOf(request.trace));
    if (passCullTests(rays, primary.triangles->size(), primary.sceneBox, request.trace.skips))
        cullForPass(passFrame(primary, rays, &threadPool), request.trace.skips, threadPool, passCull_);
    else
        cullNothing(passCull_);
    MemoryPlan cullPlan;
    planPassCull(primary, request.trace.skips, passCull_, cullPlan);  // the pass's triangles are the primary's
    double cullMs = msSince(start);
    std::vector<std::size_t> live;  // the groups with rays
    for (std::size_t k = 0; k + 1 < groups.size(); ++k)
        if (groups[k] < groups[k + 1]) live.push_back(k);
    if (sideBySideWorkers(request, threadPool.size()) > 1 && live.size() > 1 &&
        !(passCull_.skips.applied && passCull_.skips.traced.empty())) {
        // Every ray at once where the cpu backend traces them as subtrees (traceCpu), which
        // filter each triangle once for every worker; else a group a worker.
        const std::uint64_t traced = passCull_.skips.applied ? passCull_.skips.traced.size() : primary.triangles->size();
        if (cpuTracesAsSubtrees(rays.size(), traced, HitQuery::Any, request.trace, threadPool.size()))
            return traceAfterSkips(passFrame(primary, rays, &threadPool), passCull_.skips, cullPlan, cullMs, request,
                                   onPlan, {});
        return traceGroupsSideBySide(primary, rays, groups, live, request, onPlan, cullPlan, cullMs);
    }
    TraceResult whole;
    for (std::size_t k = 0; k + 1 < groups.size(); ++k) {
        if (groups[k] == groups[k + 1]) continue;
        reserveMapped(grouping_.group, groups[k + 1] - groups[k]);
        grouping_.group.assign(rays.begin() + std::ptrdiff_t(groups[k]), rays.begin() + std::ptrdiff_t(groups[k + 1]));
        TraceResult part = traceAfterSkips(passFrame(primary, grouping_.group, &threadPool), passCull_.skips,
                                           cullPlan, cullMs, request, onPlan, {});
        cullMs = 0.0;  // counted once, with the first group
        if (part.hits.empty()) return {};  // stopped at the plan
        addGroup(whole, std::move(part), rays.size());
    }
    return whole;
}

BackendDispatcher::PassTrace BackendDispatcher::traceMadeOnDevice(const FrameGeometry& primary,
                                                                   const SecondaryPass& pass,
                                                                   const BackendRequest& request, const PlanHook& onPlan) {
    // The cull's lines, with its reason for dropping nothing.
    MemoryPlan cullPlan;
    planPassCull(primary, request.trace.skips, PassCull{}, cullPlan);
    PassTrace out;
    out.result = GpuTracer(*gpu_, pool(threadsOf(request.trace)), request.trace, request.gpuTuning, pipelines_.get(),
                           nullptr, arena_.get())
                     .traceSecondary(*passSource_, primary, pass, withWorkLines(onPlan, cullPlan.work, true));
    out.result.memory.work.insert(out.result.memory.work.begin(), cullPlan.work.begin(), cullPlan.work.end());
    for (const Hit& h : out.result.hits) out.rays += h.prim != kNotTracedPrim;
    return out;
}

TraceResult BackendDispatcher::traceCulled(const FrameGeometry& g, const BackendRequest& request,
                                           const PlanHook& onPlan) {
    const auto start = Clock::now();
    cullForPass(g, request.trace.skips, pool(threadsOf(request.trace)), passCull_);
    MemoryPlan cullPlan;
    planPassCull(g, request.trace.skips, passCull_, cullPlan);
    return traceAfterSkips(g, passCull_.skips, cullPlan, msSince(start), request, onPlan, {});
}

PassCapacity BackendDispatcher::secondaryPassCapacity(const BackendRequest& request) const {
    if (request.trace.backend != Backend::Gpu || !gpu_) return {~std::uint64_t(0), "none"};
    return dacrt::secondaryPassCapacity(passSource_.get(), gpu::bufferLimits(gpu_->info(), request.gpuTuning));
}

std::uint32_t BackendDispatcher::validationErrors() const { return gpu_ ? gpu_->validationErrors() : 0; }

bool BackendDispatcher::reportValidationErrors(std::ostream& err) const {
    if (!gpu_ || !devices_.validate || gpu_->validationErrors() == 0) return false;
    for (const std::string& m : gpu_->validationMessages()) err << "dacrt: validation " << m << "\n";
    err << "dacrt: error: " << gpu_->validationErrors() << " Vulkan validation errors\n";
    return true;
}

}  // namespace dacrt
