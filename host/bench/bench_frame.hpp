#pragma once
// What every suite's frames share: the scene as a run loads it, the peers' scenes kept across
// frames as their users keep them, one primary frame timed as a user pays for it, and the
// pause after a Vulkan frame.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench.hpp"
#include "bench/bench_rows.hpp"
#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

double median(std::vector<double> v);

// The device's own time of a gpu trace (its dispatches' timestamps summed) as one more part of
// a row's phases; nothing for a trace without timestamps.
void addGpuTimestamps(const TraceResult& r, std::vector<std::pair<std::string, double>>& parts);

struct BenchScene {
    std::string name;  // unique among the run's scenes: rows key on it
    Scene scene;
    std::vector<Bounds> bounds;
    Box box;
    std::vector<Camera> cameras;
    std::string trianglesDigest;
};

// `taken`: the names of the scenes loaded before (a file named twice gets "_2").
BenchScene loadBenchScene(const std::string& path, const BenchCommand& cmd, const std::vector<std::string>& taken);

// A peer's scene, made before the frames: Embree's built (a dynamic one is rebuilt by each
// frame), the ray queries' allocated (built by the first frame). Both null for dacrt's backends.
struct PeerScenes {
    std::unique_ptr<EmbreeScene> embree;
    std::unique_ptr<RayQueryScene> rayQuery;
};
PeerScenes makePeerScenes(const BenchConfig& config, const Scene& scene, BackendDispatcher& dispatcher);

// The frame's rays and bounds live in buffers kept from frame to frame, as a renderer of a
// dynamic scene keeps them.
struct FrameBuffers {
    std::vector<Ray> rays;
    std::vector<Bounds> bounds;
};

struct FrameOutcome {
    double ms = 0.0;
    std::vector<std::pair<std::string, double>> parts;
    TraceResult result;
    // The frame as traced by dacrt's backends (into `buffers`; their secondary passes start
    // from it); empty for the peers.
    FrameGeometry geometry;
};

// A whole primary frame as a user pays for it: rays (and, for dacrt's backends, triangle
// bounds), then the backend; a peer's build or refit per its scene (`peers`).
FrameOutcome traceFrame(const BenchConfig& c, const Scene& scene, const Camera& camera, int width, int height,
                        BackendDispatcher& dispatcher, PeerScenes& peers, FrameBuffers& buffers);

// After a frame (or pass) of a Vulkan backend: an untimed pause, so that lavapipe's spinning
// worker threads do not slow whatever runs next on the same cores.
void settleAfter(Backend backend);

}  // namespace dacrt
