#pragma once
// What every suite's frames share: the run's Tracer (the public API, one per run, so one
// Vulkan device per process) and the bench's own threads, the scene as a run loads it, a peer's
// structure built before the frames, one primary frame timed as a user pays for it, and the
// pause after a Vulkan frame.
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <dacrt/tracer.hpp>

#include "bench/bench.hpp"
#include "bench/bench_rows.hpp"
#include "bench/in_loop_embree.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"
#include "core/thread_pool.hpp"
#include "library/render_inputs.hpp"

namespace dacrt {

double median(std::vector<double> v);

// The bench's own threads, a pool per count: the camera rays (on the configuration's count, as
// a renderer makes them), the float64 reference and the error measures. The traces run on the
// Tracer's.
class ThreadPools {
public:
    ThreadPool& of(unsigned threads);

private:
    std::map<unsigned, std::unique_ptr<ThreadPool>> pools_;
};

struct BenchRun {
    Tracer tracer;  // opened on the Vulkan device where one of the run's backends runs there
    ThreadPools pools;
    unsigned hardwareThreads = 1;
};

// The configuration's options on the run's Tracer (its device and validation stay).
void useConfig(Tracer& tracer, const BenchConfig& c);

// A peer's structure over `scene`, built before the frames as its users build it when a scene
// appears (a trace of one ray: the Tracer builds at a scene's first trace, and the ray queries
// compile their pipeline there; in `embree` where the rays are made in the loop); nothing for
// dacrt's backends. Returns the milliseconds it took, the pipeline's compilation aside.
double prepareStructure(BenchRun& run, const BenchConfig& c, const TraceScene& scene, InLoopEmbree& embree);

// The public hits as the oracle, the shading and the checks read them.
std::vector<Hit> hitsOf(const std::vector<RayHit>& hits);

// The trace's phases by name, then for a Vulkan trace the device's own time (its dispatches'
// timestamps summed) as "gpu timestamps".
void addTraceParts(const TraceOutput& out, std::vector<std::pair<std::string, double>>& parts);

struct BenchScene {
    std::string name;    // unique among the run's scenes: rows key on it
    TraceScene traced;   // the loaded scene, moved into the Tracer's input (library/render_inputs.hpp)
    std::vector<Bounds> bounds;  // the oracle's (error measures)
    Box box;
    std::vector<Camera> cameras;
    std::string trianglesDigest;

    const Scene& scene() const { return sceneOf(traced); }
};

// `taken`: the names of the scenes loaded before (a file named twice gets "_2").
BenchScene loadBenchScene(const std::string& path, const BenchCommand& cmd, const std::vector<std::string>& taken);

// The camera's primary rays made on `pool` into `buffer`, the memory kept from frame to frame as
// a renderer of a dynamic scene keeps it, handed to the Tracer as a batch (with the image width
// and view frustum of the camera); releaseRays gives the memory back after the trace.
RayBatch makeCameraRays(const Camera& camera, int width, int height, ThreadPool& pool, std::vector<Ray>& buffer);

struct FrameOutcome {
    double ms = 0.0;
    std::vector<std::pair<std::string, double>> parts;
    TraceOutput output;
};

// A whole primary frame as a user pays for it: the camera's rays, then the Tracer's trace
// (dacrt's backends: the triangles' bounds, then the backend; a peer: its structure rebuilt,
// refitted or kept as its build mode says, then the trace); or, for embree with its rays made
// in the loop, `embree`'s frame (the structure, then the rays made and traced together).
FrameOutcome traceStillFrame(const BenchConfig& c, const TraceScene& scene, const Camera& camera, int width, int height,
                             BenchRun& run, std::vector<Ray>& rayBuffer, InLoopEmbree& embree);

// After a frame of a Vulkan backend: an untimed pause, so that lavapipe's spinning worker
// threads do not slow whatever runs next on the same cores.
void settleAfter(Backend backend);

}  // namespace dacrt
