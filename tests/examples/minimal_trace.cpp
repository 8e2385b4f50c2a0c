// The smallest use of the library: two triangles, one ray, one call, the hit printed.
#include <cstdio>
#include <vector>

#include <dacrt/dacrt.hpp>

int main() {
    // Two triangles facing +z, the second one nearer the origin.
    const std::vector<float> positions = {-1, -1, -2, 1, -1, -2, 0, 1, -2, -1, -1, -1, 1, -1, -1, 0, 1, -1};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 3, 4, 5};
    const dacrt::TraceScene scene = dacrt::TraceScene::fromArrays(positions, indices);
    const std::vector<float> origin = {0, 0, 0}, direction = {0, 0, -1};
    const dacrt::RayBatch rays = dacrt::RayBatch::fromArrays(origin, direction);

    dacrt::Tracer tracer({.trace = {.backend = dacrt::Backend::CpuSeq}});
    const dacrt::RayHit hit = tracer.trace(scene, rays).hits[0];
    if (!hit.hit()) std::printf("ray 0 misses\n");
    else std::printf("ray 0 hits triangle %u at t = %g\n", hit.primitive, double(hit.t));
    return hit.primitive == 1 ? 0 : 1;
}
