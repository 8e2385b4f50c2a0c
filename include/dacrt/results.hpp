#pragma once
// What a trace returns: one hit per ray, the time its phases took, what it counted, and the
// plan of the memory and work it needed.
#include <cstdint>
#include <string>
#include <vector>

namespace dacrt {

// A ray's primitive id when it hit nothing within its segment.
inline constexpr std::uint32_t kNoPrimitive = 0xFFFFFFFFu;
// An any-hit answer that names no triangle (Embree's occlusion query): occluded, by some triangle.
inline constexpr std::uint32_t kUnnamedPrimitive = 0xFFFFFFFDu;

struct RayHit {
    std::uint32_t primitive = kNoPrimitive;  // the triangle's id in its scene
    float t = 0.0f;  // distance along the ray's unit direction; a miss: the ray's tmax
    float u = 0.0f;  // barycentric weight of the triangle's second vertex
    float v = 0.0f;  // barycentric weight of its third
    bool hit() const { return primitive != kNoPrimitive; }
};

// Milliseconds, measured on the host. A phase the backend does not have stays 0.
struct TraceTimings {
    double totalMs = 0.0;            // the whole call
    double skipsMs = 0.0;            // dacrt's backends: the frame's triangle skips
    double divideMs = 0.0;           // cpu, gpu: the scene's division into sub-scenes
    double step1Ms = 0.0;            // cpu: each sub-scene's own rays
    double transferMs = 0.0;         // cpu: the rays handed on between sub-scenes
    double buildMs = 0.0;            // embree, rayquery: the hierarchy's build
    double allocateMs = 0.0;         // rayquery: the device buffers
    double uploadMs = 0.0;           // gpu, rayquery
    double pipelineCompileMs = 0.0;  // gpu, rayquery: the first trace of a process compiles its pipelines
    double dispatchMs = 0.0;         // gpu, rayquery: the device's work
    double readbackMs = 0.0;         // gpu, rayquery
    double traceMs = 0.0;            // embree: the rays
};

// What the trace did. Embree and rayquery count nothing but the threads.
struct TraceCounters {
    std::uint64_t rayBoxTests = 0;
    std::uint64_t packetBoxTests = 0;    // packets of rays tested against a box at once
    std::uint64_t rayTriangleTests = 0;
    std::uint64_t leaves = 0;
    std::uint64_t raysCulled = 0;        // missed the scene's bounds
    unsigned threads = 1;
    unsigned regions = 1;                // sub-scenes the parallel scheme divided the scene into
    std::string device;                  // gpu, rayquery: the Vulkan device that traced
};

// The memory a frame needs, buffer by buffer, and its work, stage by stage (what `dacrt render
// --plan` prints).
struct FramePlan {
    struct Buffer {
        std::string name;
        std::uint64_t bytes = 0;
    };
    struct Work {
        std::string name;
        std::uint64_t count = 0;
        std::string why;
    };
    std::vector<Buffer> memory;
    std::vector<Work> work;
    std::uint64_t totalBytes() const {
        std::uint64_t total = 0;
        for (const Buffer& b : memory) total += b.bytes;
        return total;
    }
};

struct TraceOutput {
    std::vector<RayHit> hits;  // one per ray, in the batch's order
    TraceTimings timings;
    TraceCounters counters;
    FramePlan plan;
};

}  // namespace dacrt
