// A glTF scene traced from its camera: how many of a 320x240 image's rays hit, and where the
// trace spent its time.
#include <cstdio>
#include <exception>

#include <dacrt/dacrt.hpp>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s SCENE.glb\n", argv[0]);
        return 2;
    }
    try {
        const dacrt::TraceScene scene = dacrt::TraceScene::load(argv[1]);
        const dacrt::RayBatch rays = dacrt::RayBatch::fromCamera(scene, {}, 320, 240);
        dacrt::Tracer tracer;  // the cpu backend on every core
        const dacrt::TraceOutput out = tracer.trace(scene, rays);
        std::size_t hits = 0;
        for (const dacrt::RayHit& h : out.hits) hits += h.hit();
        std::printf("%zu of %zu rays hit the scene's %zu triangles (%.1f ms, %llu ray-triangle tests)\n", hits,
                    rays.size(), scene.triangleCount(), out.timings.totalMs,
                    (unsigned long long)out.counters.rayTriangleTests);
        return hits > 0 ? 0 : 1;
    } catch (const dacrt::InputError& e) {
        std::fprintf(stderr, "trace_room: %s\n", e.what());
        return 2;
    }
}
