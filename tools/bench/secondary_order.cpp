// Measures the two front-to-back orders of rays without a common near side (RayOrder: per
// split, by the sign of each ray's direction; or by direction octant first) on occlusion rays
// of a scene, closest hit and any hit, on cpu-seq and cpu, and checks that both give the same
// answers. docs/secondary-rays.md records its output.
//   cmake --build build --target dacrt_bench_secondary_order
//   build/dacrt_bench_secondary_order SCENE.glb [WIDTH HEIGHT SAMPLES REPEAT]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/camera.hpp"
#include "core/gltf_loader.hpp"
#include "core/timing.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/secondary_rays.hpp"

using namespace dacrt;

namespace {

TraceResult traceWith(const FrameGeometry& g, Backend backend, RayOrder order, ThreadPool& pool) {
    TraceOptions o;
    o.backend = backend;
    o.dacrt.rayOrder = order;
    o.regions = backend == Backend::Cpu ? pool.size() : 0;
    return traceCpu(g, o, pool);
}

bool sameAnswers(const std::vector<Hit>& a, const std::vector<Hit>& b, HitQuery query) {
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (query == HitQuery::Any ? (a[i].prim == kMissPrim) != (b[i].prim == kMissPrim)
                                   : a[i].prim != b[i].prim || std::memcmp(&a[i].t, &b[i].t, sizeof(float)) != 0)
            return false;
    }
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s SCENE.glb [WIDTH HEIGHT SAMPLES REPEAT]\n", argv[0]);
        return 2;
    }
    const int width = argc > 2 ? std::atoi(argv[2]) : 320, height = argc > 3 ? std::atoi(argv[3]) : 240;
    const std::uint32_t samples = argc > 4 ? std::uint32_t(std::atoi(argv[4])) : 4;
    const int repeat = argc > 5 ? std::atoi(argv[5]) : 3;
    const Scene scene = loadGltf(argv[1]);
    const std::vector<Bounds> bounds = allTriangleBounds(scene.triangles);
    const Box box = sceneBounds(scene.triangles);
    const Camera camera = makeCameras(scene, box, {}, double(width) / double(height)).front();
    const std::vector<Ray> primary = primaryRays(camera, width, height);
    ThreadPool pool(2), one(1);
    TraceOptions o;
    const TraceResult hits = traceCpu(frameGeometry(scene.triangles, bounds, primary, box, std::uint32_t(width)), o, pool);
    SecondaryPass pass;
    pass.kind = shared::kPassOcclusion;
    pass.raysPerHit = samples;
    pass.sampleSeed = 1;
    std::printf("%s, %dx%d, %u occlusion rays per hit, best of %d\n", argv[1], width, height, samples, repeat);
    std::printf("%-8s %-12s %-8s %-9s %10s %10s\n", "query", "length", "backend", "order", "rays", "ms");
    const float diagonal = float(glm::length(glm::dvec3(box.extent())));
    for (const float length : {0.1f * diagonal, kNoHitT}) {
        pass.occlusionDistance = length;
        const SecondaryRays rays = makeSecondaryRays(pass, primary, hits.hits, scene.triangles, pool);
        for (const HitQuery query : {HitQuery::Closest, HitQuery::Any}) {
            FrameGeometry g = secondaryFrame(scene.triangles, bounds, rays.rays, box);
            g.query = query;
            for (const Backend backend : {Backend::CpuSeq, Backend::Cpu}) {
                std::vector<Hit> reference;
                for (const RayOrder order : {RayOrder::PerSplit, RayOrder::Octants}) {
                    double best = 1e300;
                    TraceResult r;
                    for (int k = 0; k < repeat; ++k) {
                        const auto start = Clock::now();
                        r = traceWith(g, backend, order, backend == Backend::Cpu ? pool : one);
                        best = std::min(best, msSince(start));
                    }
                    if (reference.empty()) reference = r.hits;
                    else if (!sameAnswers(reference, r.hits, query)) {
                        std::fprintf(stderr, "the two orders disagree\n");
                        return 1;
                    }
                    std::printf("%-8s %-12s %-8s %-9s %10zu %10.1f\n", query == HitQuery::Any ? "any" : "closest",
                                length == kNoHitT ? "unbounded" : "0.1 diag", toString(backend).c_str(),
                                order == RayOrder::PerSplit ? "per-split" : "octants", rays.rays.size(), best);
                }
            }
        }
    }
    return 0;
}
