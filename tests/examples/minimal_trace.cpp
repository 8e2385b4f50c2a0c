// The smallest use of the library: two triangles, one ray, one call, the hit printed.
#include <cstdio>
#include <vector>

#include "core/camera.hpp"
#include "core/thread_pool.hpp"
#include "cpu/cpu_tracers.hpp"

int main() {
    using namespace dacrt;
    // Two triangles facing +z, the second one nearer the origin.
    const std::vector<Triangle> triangles = {
        Triangle{{-1, -1, -2}, 0, {1, -1, -2}, 0, {0, 1, -2}, 0},
        Triangle{{-1, -1, -1}, 0, {1, -1, -1}, 0, {0, 1, -1}, 0},
    };
    const std::vector<Ray> rays = {makeRay({0, 0, 0}, {0, 0, -1})};
    const std::vector<Bounds> bounds = allTriangleBounds(triangles);

    TraceOptions options;
    options.backend = Backend::CpuSeq;
    ThreadPool pool(1);
    const TraceResult result = traceCpu(frameGeometry(triangles, bounds, rays, sceneBounds(triangles)), options, pool);

    const Hit& hit = result.hits[0];
    if (hit.prim == kMissPrim) std::printf("ray 0 misses\n");
    else std::printf("ray 0 hits triangle %u at t = %g\n", hit.prim, double(hit.t));
    return hit.prim == 1 ? 0 : 1;
}
