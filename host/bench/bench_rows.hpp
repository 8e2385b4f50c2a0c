#pragma once
// What the bench command measures: a configuration (a Tracer's options with a name) and the
// row it yields per scene.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <dacrt/tracer.hpp>

#include "cpu/options.hpp"  // the options' names
#include "oracle/error_metrics.hpp"

namespace dacrt {

struct BenchConfig {
    std::string series;  // backend, or "embree static"
    std::string name;    // "default" or the option values that differ from it
    TracerOptions options;  // the Vulkan device and validation are the run's (Tracer::setOptions)
    bool isDefault = false;
    // embree: Embree held by the bench and every ray made in its tracing loop, as a renderer on
    // it runs (bench/in_loop_embree.hpp); false: rays made and stored first, then traced through
    // the Tracer (the rows named "stored rays").
    bool raysInLoop = false;
    Backend backend() const { return options.trace.backend; }
    unsigned threads() const { return traceThreads(options.trace); }
};

struct BenchRow {
    std::string scene;
    std::size_t triangles = 0;
    std::size_t raysPerFrame = 0;
    int cameras = 0;
    BenchConfig config;
    unsigned regions = 0;
    int divisionAxis = -1;
    double frameMsMin = 0.0;
    double frameMsMedian = 0.0;
    std::vector<std::pair<std::string, double>> partsMs;  // mean per frame
    ErrorMetrics errors;
    bool pareto = false;
    std::optional<double> speedupOverSequential;
};

// --suite passes: one pass of a lit frame (or the whole frame) per scene and configuration.
struct PassRow {
    std::string scene;
    std::size_t triangles = 0;
    std::size_t pixels = 0;  // primary rays per frame
    int cameras = 0;
    BenchConfig config;
    int passIndex = 0;        // 0: primary, then the secondary passes in the order they run
    std::string pass;         // "primary", the secondary pass's name, or "frame" (every pass)
    std::string kind;         // primary, shadow, occlusion, frame
    std::uint32_t raysPerHit = 1;
    double slotsPerFrame = 0.0;  // mean over the cameras
    double raysPerFrame = 0.0;   // rays made, mean over the cameras
    double msMin = 0.0;          // each camera's fastest frame, mean over the cameras
    double msMedian = 0.0;       // each camera's median, mean over the cameras
    double msMean = 0.0;         // every frame's, mean (what partsMs divide)
    std::vector<std::pair<std::string, double>> partsMs;  // mean per frame
    std::uint64_t checkedSlots = 0;  // summed over the cameras
    // Slots whose answer differs from cpu-seq's: the visibility (no ray, open, blocked) of a
    // secondary pass; the primitive of a primary ray, and for dacrt's backends its depth bit
    // for bit too.
    std::uint64_t mismatches = 0;
    bool exactRequired = false;  // dacrt's backends: any mismatch fails the run
    std::uint64_t framesTogether = 0;  // a secondary pass's timed frames traced with the others (--pass-tracing)
};

// --suite animation: one configuration's work for one frame, from the run of the frame (of its
// --repeat timed runs) whose work time is the median, so that its phases add up.
struct AnimationFrameRow {
    std::string scene;
    std::int64_t frame = 0;
    double timeS = 0.0;
    std::size_t triangles = 0;
    bool topologyChanged = false;  // the triangle count differs from the previous frame's
    BenchConfig config;
    std::size_t rays = 0;
    double evaluateMs = 0.0;        // the animation evaluated into the frame's scene, the same for every configuration (median run)
    double prepareMs = 0.0;
    std::optional<double> buildMs;  // a peer's build or refit
    double traceMs = 0.0;
    double workMs = 0.0;            // prepare + build + trace: the backend's frame
    double copyMs = 0.0;            // the frame's vertex copy, not counted (reported for the peers)
    bool rebuilt = false;           // a refit peer rebuilt (the triangle count changed)
    std::vector<std::pair<std::string, double>> partsMs;
    // Pixels whose primitive differs from cpu-seq's (dacrt's backends: or whose depth differs
    // in any bit); for the peers, how many of them are near ties (error_metrics.hpp, with
    // cpu-seq's hits as the reference) and how many real.
    std::uint64_t differing = 0;
    std::uint64_t nearTies = 0;
    std::uint64_t realErrors = 0;
    bool exactRequired = false;     // dacrt's backends: any difference fails the run
    double initialBuildMs = 0.0;    // a peer's structure built from the first frame, before the frames

    double totalMs() const { return evaluateMs + workMs; }
};

// A scene of an animation run: what holds for all its rows.
struct AnimationScene {
    std::string name;
    std::string path;
    std::vector<std::string> animations;  // the file's, "name (start-end s)"
    bool animated = false;
    std::vector<std::int64_t> topologyChanges;  // frames whose triangle count differs from the previous frame's
};

}  // namespace dacrt
