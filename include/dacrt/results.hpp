#pragma once
// What a trace returns: one hit per ray, the time its phases took, what it counted, and the
// plan of the memory and work it needed.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <dacrt/device_report.hpp>

namespace dacrt {

// A ray's primitive id when it hit nothing within its segment.
inline constexpr std::uint32_t kNoPrimitive = 0xFFFFFFFFu;
// An any-hit answer that names no triangle (Embree's occlusion query): occluded, by some triangle.
inline constexpr std::uint32_t kUnnamedPrimitive = 0xFFFFFFFDu;
// A frame pass's slot that made no ray (its primary ray missed, or its surface cannot send one).
inline constexpr std::uint32_t kNotTracedPrimitive = 0xFFFFFFFEu;

struct RayHit {
    std::uint32_t primitive = kNoPrimitive;  // the triangle's id in its scene
    float t = 0.0f;  // distance along the ray's unit direction; a miss: the ray's tmax
    float u = 0.0f;  // barycentric weight of the triangle's second vertex
    float v = 0.0f;  // barycentric weight of its third
    bool hit() const { return primitive != kNoPrimitive && primitive != kNotTracedPrimitive; }
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
    // The phases run, with the names `dacrt render --stats` gives them, in the order they ran.
    struct Phase {
        std::string name;
        double ms = 0.0;
    };
    std::vector<Phase> phases;
    std::vector<double> step1RegionMs;  // cpu: each region's Step 1 work item, for load balance
};

// What the trace did. Embree and rayquery count nothing but the threads.
struct TraceCounters {
    std::uint64_t rayBoxTests = 0;
    std::uint64_t packetBoxTests = 0;    // packets of rays tested against a box at once
    std::uint64_t rayTriangleTests = 0;         // a leaf's rays times its triangles, summed over leaves
    std::uint64_t rayTriangleTestsSkipped = 0;  // cpu: of those, pairs a leaf's ray groups ruled out unrun
    std::uint64_t leaves = 0;
    std::uint64_t tightBoxes = 0;       // DACRT backends: nodes traced inside the box of their triangles' bounds
    std::uint64_t raysCulled = 0;        // missed the scene's bounds
    std::uint64_t raysFinishedWithoutHit = 0;  // cpu: finished early, unable to reach a further region
    std::uint64_t raysFinishedStep1 = 0;       // in their own region's Step 1 (cpu-seq: every ray)
    struct Round {
        std::string name;
        std::uint64_t raysFinished = 0;
    };
    std::vector<Round> transferRounds;   // cpu: the rounds that hand rays on, in execution order
    std::uint64_t transferWorkItems = 0;
    std::uint64_t transferWorkItemsSkipped = 0;
    unsigned threads = 1;
    unsigned regions = 1;                // sub-scenes the parallel scheme divided the scene into
    int divisionAxis = -1;               // the regions' axis: 0 x, 1 y, 2 z; -1 no division
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
    std::optional<DeviceReport> gpu;  // gpu only
};

}  // namespace dacrt
