#include "bench/bench_configs.hpp"

#include <sstream>

#include "core/errors.hpp"

namespace dacrt {

void recordConfig(nlohmann::ordered_json& row, const BenchConfig& c) {
    row["backend"] = toString(c.backend());
    row["series"] = c.series;
    row["config"] = c.name;
    row["default"] = c.isDefault;
    row["options"] = optionText(c);
    row["threads"] = c.threads();
}

std::string configLabel(const BenchConfig& c) { return c.name == "default" ? c.series : c.series + " " + c.name; }

std::string optionText(const BenchConfig& c) {
    std::ostringstream s;
    if (c.backend() == Backend::RayQuery) return "build=" + toString(c.options.rayQueryBuild);
    if (c.backend() == Backend::Embree) {
        s << "build=" << toString(c.options.embree.build) << " robust=" << (c.options.embree.robust ? "on" : "off")
          << " rays=" << (c.options.embree.packets ? "rtcIntersect16_4x4" : "rtcIntersect1")
          << " rays_made=" << (c.raysInLoop ? "in_loop" : "stored_first") << " threads=" << c.threads()
          << " face_filter=" << (c.options.embree.faceFilter ? "on" : "off");
        return s.str();
    }
    const DacrtOptions d = c.options.trace.dacrt.resolvedFor(c.backend());
    // The gpu's leaf rule depends on its device (gpu::kernelLeafRule): limits as given, else auto.
    const bool gpu = c.backend() == Backend::Gpu;
    auto limit = [&](std::uint32_t given, std::uint32_t resolved) {
        return !gpu ? std::to_string(resolved) : given ? std::to_string(given) : std::string("auto");
    };
    s << "intersector=" << toString(d.intersector) << " triangle_filter=" << toString(d.triangleFilter)
      << " precision=" << toString(d.precision) << " split=" << toString(d.split)
      << " ray_limit=" << limit(c.options.trace.dacrt.rayLimit, d.rayLimit)
      << " tri_limit=" << limit(c.options.trace.dacrt.triLimit, d.triLimit) << " axis=" << toString(c.options.trace.axis) << " regions=" << c.options.trace.regions
      << " threads=" << c.threads();
    if (d.splitCost != SplitCost::Limits) s << " split_cost=" << toString(d.splitCost);
    if (!d.packets) s << " packets=off";
    if (!d.tightBoxes) s << " tight_boxes=off";
    if (d.packets && d.packetFlush != kPacketFlushDefault) s << " packet_flush=" << d.packetFlush;
    if (d.rayGrouping != DacrtOptions{}.rayGrouping) s << " ray_grouping=" << toString(d.rayGrouping);
    if (d.passTracing != DacrtOptions{}.passTracing) s << " pass_tracing=" << toString(d.passTracing);
    if (c.backend() == Backend::Gpu)
        s << " ray_groups=" << (c.options.gpu.rayGroups ? std::to_string(c.options.gpu.rayGroups) : "auto");
    if (c.backend() == Backend::Gpu)
        s << " leaf_balance=" << (c.options.gpu.leafBalance ? std::to_string(*c.options.gpu.leafBalance) : "auto");
    if (c.backend() == Backend::Gpu && c.options.gpu.profile != GpuProfile::Auto)
        s << " profile=" << toString(c.options.gpu.profile);
    const SkipSwitches& k = c.options.trace.skips;
    if (!(k == SkipSwitches{}))
        s << " no_skip=" << (k.backFaces ? "" : "backfaces,") << (k.frustum ? "" : "frustum,") << (k.uploads ? "" : "uploads,") << (k.subScenes ? "" : "subscenes,") << (k.passRays ? "" : "passrays,");
    return s.str();
}

BenchConfig baseConfig(Backend b, unsigned hardwareThreads) {
    BenchConfig c;
    c.series = toString(b);
    c.name = "default";
    c.options.trace.backend = b;
    // cpu-seq runs on one thread; the ray queries run on the device, and take no thread count
    // (they report every core's, as the threads their host work may use).
    c.options.trace.threads = b == Backend::CpuSeq ? 1u : b == Backend::RayQuery ? 0u : hardwareThreads;
    c.isDefault = true;
    c.raysInLoop = b == Backend::Embree;  // as Embree's users run it
    return c;
}

namespace {

// A non-default row of base's series: base changed by `change`, named `name`.
template <typename Change>
BenchConfig variantOf(const BenchConfig& base, const std::string& name, Change&& change) {
    BenchConfig c = base;
    c.name = name;
    c.isDefault = false;
    change(c);
    return c;
}

// base as the series of one build mode of a peer ("embree refit"): the default is the dynamic one.
template <typename Build, typename SetBuild>
BenchConfig buildSeries(const BenchConfig& base, const std::string& peer, Build build, SetBuild setBuild) {
    BenchConfig c = base;
    c.series = peer + " " + toString(build);
    setBuild(c, build);
    c.isDefault = build == Build::Dynamic;
    return c;
}

// As a Vulkan user builds for each case (the device's own ray tracing).
std::vector<BenchConfig> rayQuerySweep(const BenchConfig& base) {
    std::vector<BenchConfig> out;
    for (RayQueryBuild build : {RayQueryBuild::Dynamic, RayQueryBuild::Refit, RayQueryBuild::Static})
        out.push_back(buildSeries(base, "rayquery", build, [](BenchConfig& row, RayQueryBuild b) { row.options.rayQueryBuild = b; }));
    return out;
}

// As Embree's users run each case: a series per build mode, its rays made in the tracing loop,
// robust mode on (the default, exact on the models) and off; then the same with its rays made
// and stored first and traced through the Tracer (what the rows were before issue 32), and
// single rays against packets once (on stored rays: the in-loop tracer is the packets').
std::vector<BenchConfig> embreeSweep(const BenchConfig& base) {
    std::vector<BenchConfig> out;
    for (EmbreeBuild build : {EmbreeBuild::Dynamic, EmbreeBuild::Refit, EmbreeBuild::Static}) {
        BenchConfig c = buildSeries(base, "embree", build, [](BenchConfig& row, EmbreeBuild b) { row.options.embree.build = b; });
        out.push_back(c);
        c.isDefault = false;
        BenchConfig stored = c;
        stored.name = kStoredRays;
        stored.raysInLoop = false;
        c.name = "robust=off";
        c.options.embree.robust = false;
        out.push_back(c);
        out.push_back(stored);
    }
    out.push_back(variantOf(base, "rtcIntersect1, " + std::string(kStoredRays), [](BenchConfig& c) {
        c.options.embree.packets = false;
        c.raysInLoop = false;
    }));
    out.back().series = "embree dynamic";
    // Without the face rule's filter: what a user whose meshes show no back face runs.
    out.push_back(variantOf(base, "face-filter=off", [](BenchConfig& c) { c.options.embree.faceFilter = false; }));
    out.back().series = "embree dynamic";
    return out;
}

}  // namespace

std::vector<BenchConfig> sweepConfigs(Backend b, unsigned hardwareThreads, unsigned gpuDefaultRegions,
                                      std::uint32_t gpuDefaultRayGroups, std::uint32_t gpuDefaultLeafBalance) {
    const BenchConfig base = baseConfig(b, hardwareThreads);
    if (b == Backend::RayQuery) return rayQuerySweep(base);
    if (b == Backend::Embree) return embreeSweep(base);
    std::vector<BenchConfig> out;
    auto variant = [&](const std::string& name, auto&& change) { out.push_back(variantOf(base, name, change)); };
    out.push_back(base);
    if (b == Backend::Brute) return out;
    const bool cpu = b == Backend::Cpu || b == Backend::CpuSeq;
    if (cpu) {
        variant("intersector=moller-trumbore", [](BenchConfig& c) { c.options.trace.dacrt.intersector = Intersector::MollerTrumbore; });
        variant("triangle-filter=sat", [](BenchConfig& c) { c.options.trace.dacrt.triangleFilter = TriangleFilter::Sat; });
        variant("triangle-filter=mora", [](BenchConfig& c) { c.options.trace.dacrt.triangleFilter = TriangleFilter::Mora; });
        variant("precision=f64", [](BenchConfig& c) { c.options.trace.dacrt.precision = Precision::F64; });
        variant("split=centroid-mean", [](BenchConfig& c) { c.options.trace.dacrt.split = SplitMethod::CentroidMean; });
        variant("split=sampled-mean", [](BenchConfig& c) { c.options.trace.dacrt.split = SplitMethod::SampledMean; });
        // Nabata et al. 2013's ray-sampling cost: with packets (it decides below their levels)
        // and without (it decides from the top).
        variant("split-cost=ray-sampling", [](BenchConfig& c) { c.options.trace.dacrt.splitCost = SplitCost::RaySampling; });
        variant("split-cost=ray-sampling packets=off", [](BenchConfig& c) {
            c.options.trace.dacrt.splitCost = SplitCost::RaySampling;
            c.options.trace.dacrt.packets = false;
        });
    }
    variant("tight-boxes=off", [](BenchConfig& c) { c.options.trace.dacrt.tightBoxes = false; });
    const DacrtOptions defaults = base.options.trace.dacrt.resolvedFor(b);
    variant("packets=off", [](BenchConfig& c) { c.options.trace.dacrt.packets = false; });
    for (std::uint32_t f : {4u, 64u, 256u})
        if (f != defaults.packetFlush)
            variant("packet-flush=" + std::to_string(f), [f](BenchConfig& c) { c.options.trace.dacrt.packetFlush = f; });
    if (cpu) {
        for (std::uint32_t l : {4u, 8u, 16u, 32u, 64u})
            if (l != defaults.rayLimit)
                variant("ray-limit=" + std::to_string(l), [l](BenchConfig& c) { c.options.trace.dacrt.rayLimit = l; });
        for (std::uint32_t l : {8u, 16u, 32u, 64u, 128u})
            if (l != defaults.triLimit)
                variant("tri-limit=" + std::to_string(l), [l](BenchConfig& c) { c.options.trace.dacrt.triLimit = l; });
    } else {
        // A leaf limit given turns the leaf balance's default off: these rows are the limits
        // alone (and leaf-balance=0 the limits' default).
        for (std::uint32_t l : {8u, 16u, 32u, 64u, 128u})
            if (l != defaults.rayLimit)
                variant("leaf-limits=" + std::to_string(l), [l](BenchConfig& c) { c.options.trace.dacrt.rayLimit = c.options.trace.dacrt.triLimit = l; });
        for (std::uint32_t balance : {0u, 12u, kCpuProfileLeafBalance, 32u})
            if (balance != gpuDefaultLeafBalance)
                variant("leaf-balance=" + std::to_string(balance), [balance](BenchConfig& c) { c.options.gpu.leafBalance = balance; });
    }
    if (b == Backend::CpuSeq) return out;
    const unsigned defaultRegions = b == Backend::Cpu ? hardwareThreads : gpuDefaultRegions;
    for (unsigned r : {1u, 2u, 4u, 8u, 16u, 64u})
        if (r != defaultRegions)
            variant("regions=" + std::to_string(r), [r](BenchConfig& c) { c.options.trace.regions = r; });
    for (DivisionAxis a : {DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z})
        variant("axis=" + toString(a), [a](BenchConfig& c) { c.options.trace.axis = a; });
    if (b == Backend::Gpu)
        for (std::uint32_t groups : {1u, 2u, 4u})
            if (groups != gpuDefaultRayGroups)
                variant("ray-groups=" + std::to_string(groups), [groups](BenchConfig& c) { c.options.gpu.rayGroups = groups; });
    return out;
}

std::vector<BenchConfig> skipConfigs(Backend b, unsigned hardwareThreads) {
    if (b == Backend::Embree) {
        BenchConfig noFilter = baseConfig(b, hardwareThreads);
        noFilter.name = "face-filter=off";
        noFilter.isDefault = false;
        noFilter.options.embree.faceFilter = false;
        return {baseConfig(b, hardwareThreads), noFilter};
    }
    if (isPeer(b)) return {baseConfig(b, hardwareThreads)};
    std::vector<BenchConfig> out = {baseConfig(b, hardwareThreads)};
    auto off = [&](const std::string& name, auto&& change) {
        BenchConfig c = out.front();
        c.name = "no-skip=" + name;
        c.isDefault = false;
        change(c.options.trace.skips);
        out.push_back(c);
    };
    off("backfaces", [](SkipSwitches& s) { s.backFaces = false; });
    off("frustum", [](SkipSwitches& s) { s.frustum = false; });
    if (b == Backend::Gpu) off("uploads", [](SkipSwitches& s) { s.uploads = false; });
    if (b == Backend::Cpu) off("subscenes", [](SkipSwitches& s) { s.subScenes = false; });
    off("all", [](SkipSwitches& s) { s = SkipSwitches{false, false, false, false, false}; });
    return out;
}

std::vector<BenchConfig> peerConfigs(Backend b, unsigned hardwareThreads) {
    if (isPeer(b)) return sweepConfigs(b, hardwareThreads, 0, 0, 0);
    return {baseConfig(b, hardwareThreads)};
}

std::vector<BenchConfig> passesConfigs(Backend b, unsigned hardwareThreads) {
    std::vector<BenchConfig> out;
    if (isPeer(b)) {
        for (const BenchConfig& c : sweepConfigs(b, hardwareThreads, 0, 0, 0))
            if (c.name == "default" || c.name == kStoredRays) out.push_back(c);
        return out;
    }
    out.push_back(baseConfig(b, hardwareThreads));
    auto variant = [&](const std::string& name, auto&& set) {
        BenchConfig c = out.front();
        c.name = name;
        c.isDefault = false;
        set(c.options.trace.dacrt);
        out.push_back(c);
    };
    // The nodes' own boxes, without the box of their triangles (docs/benchmarks.md, "Tight node
    // boxes"; the kernel's: docs/gpu.md).
    const auto cellsOnly = [](DacrtOptions& d) { d.tightBoxes = false; };
    if (b == Backend::Gpu) variant("tight-boxes=off", cellsOnly);
    if (b != Backend::Cpu) return out;
    // The secondary rays' order (docs/benchmarks.md, "Rays grouped by octant").
    for (RayGrouping grouping : {RayGrouping::Slots, RayGrouping::Octant, RayGrouping::OctantCalls})
        variant("ray-grouping=" + toString(grouping), [grouping](DacrtOptions& d) { d.rayGrouping = grouping; });
    // The passes apart and together, whichever the default chose (docs/benchmarks.md, "A frame's
    // passes traced together").
    for (PassTracing tracing : {PassTracing::Apart, PassTracing::Together})
        variant("pass-tracing=" + toString(tracing), [tracing](DacrtOptions& d) { d.passTracing = tracing; });
    variant("tight-boxes=off", cellsOnly);
    return out;
}

std::vector<BenchConfig> animationConfigs(Backend b, unsigned hardwareThreads) {
    std::vector<BenchConfig> out;
    if (!isPeer(b)) return {baseConfig(b, hardwareThreads)};
    for (const BenchConfig& c : sweepConfigs(b, hardwareThreads, 0, 0, 0)) {
        const bool staticBuild = b == Backend::Embree ? c.options.embree.build == EmbreeBuild::Static
                                                      : c.options.rayQueryBuild == RayQueryBuild::Static;
        if (c.name == "default" && !staticBuild) out.push_back(c);
    }
    return out;
}

// The source's Table 5.1 (threads, and two regions per thread) and Figure 5.3 (division axes),
// with the cpu backend's default beside them.
std::vector<BenchConfig> table51Configs(Backend b, unsigned hardwareThreads) {
    std::vector<BenchConfig> out;
    if (b == Backend::CpuSeq) {
        out.push_back(baseConfig(b, hardwareThreads));
        return out;
    }
    auto config = [&](unsigned threads, unsigned regions, DivisionAxis axis) {
        BenchConfig c = baseConfig(b, hardwareThreads);
        c.isDefault = false;
        c.options.trace.threads = b == Backend::Cpu ? threads : hardwareThreads;
        c.options.trace.regions = regions;
        c.options.trace.axis = axis;
        c.name = (b == Backend::Cpu ? "threads=" + std::to_string(threads) + " " : std::string()) +
                 "regions=" + std::to_string(regions) + " axis=" + toString(axis);
        out.push_back(c);
    };
    const DivisionAxis axes[] = {DivisionAxis::Best, DivisionAxis::X, DivisionAxis::Y, DivisionAxis::Z};
    if (b == Backend::Cpu) {
        // The backend as it runs by default (image bands on every core, no division), beside
        // the source's setups of threads and regions.
        out.push_back(baseConfig(b, hardwareThreads));
        const std::pair<unsigned, unsigned> setups[] = {{1, 1}, {2, 2}, {4, 4}, {1, 2}, {2, 4}, {4, 8}};
        for (const auto& [threads, regions] : setups)
            for (DivisionAxis a : axes) config(threads, regions, a);
    } else if (b == Backend::Gpu) {
        for (unsigned regions : {1u, 2u, 4u, 8u, 16u})
            for (DivisionAxis a : axes)
                if (a == DivisionAxis::Best || regions == 2 || regions == 4) config(0, regions, a);
    } else {
        throw InputError("--suite table51 compares the DACRT backends (cpu-seq, cpu, gpu), not " + toString(b));
    }
    return out;
}

}  // namespace dacrt
