// The C++ API's side of the Python module's benchmark (python/bench/cast_rays_bench.py,
// docs/python.md): the rays of a raw float32 file (six floats per ray, origin then direction,
// as numpy's tofile writes a (N, 6) array) traced into a glTF scene through RayBatch::fromRays
// and Tracer::trace, each repeat timed from the arrays to the hits, as cast_rays is.
//
//   dacrt_bench_api_rays SCENE RAYS.f32 BACKEND THREADS WARMUP REPEAT [normalize]
//
// Prints one line per timed repeat, "trace_ms T", then "hits H id_sum S" (the answers, for the
// script to check that both sides traced the same rays alike).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <dacrt/dacrt.hpp>

namespace {

std::vector<float> readRays(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw dacrt::InputError(path + ": cannot read");
    const std::streamsize bytes = in.tellg();
    std::vector<float> rays(std::size_t(bytes) / sizeof(float));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(rays.data()), std::streamsize(rays.size() * sizeof(float)));
    return rays;
}

int run(int argc, char** argv) {
    if (argc < 7) {
        std::fprintf(stderr, "usage: %s SCENE RAYS.f32 BACKEND THREADS WARMUP REPEAT [normalize]\n", argv[0]);
        return 2;
    }
    const dacrt::TraceScene scene = dacrt::TraceScene::load(argv[1]);
    const std::vector<float> rays = readRays(argv[2]);
    dacrt::TracerOptions options;
    const std::optional<dacrt::Backend> backend = dacrt::backendNamed(argv[3]);
    if (!backend) throw dacrt::InputError(std::string(argv[3]) + ": not a backend");
    options.trace.backend = *backend;
    options.trace.threads = unsigned(std::stoul(argv[4]));
    const int warmup = std::stoi(argv[5]), repeat = std::stoi(argv[6]);
    const auto length = argc > 7 && std::string(argv[7]) == "normalize" ? dacrt::DirectionLength::Normalize
                                                                        : dacrt::DirectionLength::AsGiven;
    dacrt::Tracer tracer(options);
    dacrt::TraceOutput out;
    for (int k = 0; k < warmup + repeat; ++k) {
        const auto start = std::chrono::steady_clock::now();
        out = tracer.trace(scene, dacrt::RayBatch::fromRays(rays, {}, {}, length));
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (k >= warmup) std::printf("trace_ms %.3f\n", ms);
    }
    std::uint64_t hits = 0, idSum = 0;
    for (const dacrt::RayHit& h : out.hits)
        if (h.hit()) ++hits, idSum += h.primitive;
    std::printf("hits %llu id_sum %llu\n", static_cast<unsigned long long>(hits), static_cast<unsigned long long>(idSum));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "dacrt_bench_api_rays: %s\n", e.what());
        return 2;
    }
}
