// libFuzzer target (docs/fuzzing.md): any bytes, loaded as a glTF file from memory.
//
// 1. The bytes as they are: the loader reads a .glb when they start with the magic "glTF",
//    else the text of a .gltf.
// 2. Text (no magic) is also wrapped into a .glb container as its JSON chunk, so that every
//    mutation of the JSON reaches the binary path too.
//
// Bad input must end in dacrt::InputError; anything else leaving the loader (another
// exception, a crash, a sanitizer report, an allocation past libFuzzer's -malloc_limit_mb)
// is a finding. A scene that loads with a few triangles is traced in a tiny frame, from its
// own camera and from the default front view, by cpu-seq, cpu (the parallel scheme) and brute
// force; the three must agree bit for bit (primitive id and t), as docs/correctness.md
// promises, else the target aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/gltf_loader.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "cpu/cpu_tracers.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace dacrt;
using fuzz::verbose;

constexpr int kWidth = 8;
constexpr int kHeight = 6;
// Tracing cost cap: brute force is triangles x rays tests per frame.
constexpr std::size_t kMaxTriangles = 2000;

[[noreturn]] void finding(const char* what, std::size_t pixel, const Hit& a, const Hit& b) {
    std::fprintf(stderr, "gltf_fuzzer: %s differ at pixel %zu: prim %u t %a vs prim %u t %a\n", what, pixel,
                 a.prim, double(a.t), b.prim, double(b.t));
    std::abort();
}

void compare(const char* what, const std::vector<Hit>& a, const std::vector<Hit>& b) {
    if (a.size() != b.size()) {
        std::fprintf(stderr, "gltf_fuzzer: %s: %zu and %zu hits\n", what, a.size(), b.size());
        std::abort();
    }
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].prim != b[i].prim || std::memcmp(&a[i].t, &b[i].t, sizeof(float)) != 0) finding(what, i, a[i], b[i]);
}

ThreadPool& pool() {
    static ThreadPool p(1);  // inline: the fuzzer stays on one core and deterministic
    return p;
}

void traceFrame(const Scene& scene) {
    const std::vector<Bounds> bounds = allTriangleBounds(scene.triangles);
    const Box box = sceneBounds(scene.triangles);
    std::vector<Ray> rays;
    try {
        const std::vector<Camera> cameras = makeCameras(scene, box, CameraOptions{}, double(kWidth) / kHeight);
        rays = primaryRays(cameras.front(), kWidth, kHeight);
    } catch (const InputError& e) {
        if (verbose()) std::fprintf(stderr, "  camera refused: %s\n", e.what());
        return;  // a camera the scene cannot be seen from: refused, as the command line does
    }
    const FrameGeometry geometry = frameGeometry(scene.triangles, bounds, rays, box, kWidth);

    TraceOptions brute;
    brute.backend = Backend::Brute;
    TraceOptions seq;
    seq.backend = Backend::CpuSeq;
    TraceOptions parallel;
    parallel.backend = Backend::Cpu;
    parallel.threads = 1;
    parallel.regions = 4;
    TraceOptions seqScalar = seq;  // the scalar filters and leaves (a non-default test) and no packets
    seqScalar.dacrt.triangleFilter = TriangleFilter::Sat;
    TraceOptions seqPacketsToLeaves = seq;
    seqPacketsToLeaves.dacrt.packetFlush = 1;

    const TraceResult reference = traceCpu(geometry, brute, pool());
    compare("cpu-seq and brute", traceCpu(geometry, seq, pool()).hits, reference.hits);
    compare("cpu (4 regions) and brute", traceCpu(geometry, parallel, pool()).hits, reference.hits);
    compare("cpu-seq (SAT filter, scalar) and brute", traceCpu(geometry, seqScalar, pool()).hits, reference.hits);
    compare("cpu-seq (packets to the leaves) and brute", traceCpu(geometry, seqPacketsToLeaves, pool()).hits,
            reference.hits);
    if (verbose()) {
        std::size_t hits = 0;
        for (const Hit& h : reference.hits) hits += h.prim != kMissPrim;
        std::fprintf(stderr, "  traced %zu rays, %zu hits, three backends agree\n", rays.size(), hits);
    }
}

void loadAndTrace(std::span<const unsigned char> bytes, const char* name) {
    std::optional<Scene> loaded = fuzz::load(bytes, name);
    if (!loaded) return;
    Scene& scene = *loaded;
    if (scene.triangles.empty() || scene.triangles.size() > kMaxTriangles) return;
    traceFrame(scene);
    if (scene.camera) {  // and the default front view, which frames the triangles
        scene.camera.reset();
        traceFrame(scene);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::span<const unsigned char> bytes(data, size);
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    loadAndTrace(bytes, binary ? "fuzz.glb" : "fuzz.gltf");
    if (!binary) {
        const std::vector<unsigned char> glb = fuzz::glbWithHeader(fuzz::glbChunks(bytes, {}));
        loadAndTrace(glb, "fuzz-wrapped.glb");
    }
    return 0;
}
