#pragma once
// What every tracer takes and returns.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "scene.hpp"

namespace dacrt {

enum class Backend { Brute, CpuSeq, Cpu, Gpu, Embree };
enum class SplitMethod { SpatialMedian, CentroidMean, SampledMean };
enum class DivisionAxis { Best, X, Y, Z };
// Ray/triangle test of a DACRT leaf. Watertight is exact up to rounding and never leaks
// through shared edges; Moller-Trumbore is the classic faster test without that guarantee.
enum class Intersector { Watertight, MollerTrumbore };
// Which triangles a DACRT node keeps for a child cell. Bounds (the default) and Sat are
// conservative; Mora is deliberately inexact (docs/benchmarks.md measures its price).
enum class TriangleFilter { Bounds, Sat, Mora };
// Arithmetic of the leaf's ray/triangle test: the filters stay float32 in both cases (their
// margin also covers the smaller float64 rounding).
enum class Precision { F32, F64 };

std::string toString(Backend b);
std::string toString(SplitMethod s);
std::string toString(DivisionAxis a);
std::string toString(Intersector i);
std::string toString(TriangleFilter f);
std::string toString(Precision p);

// Leaf limits of each backend when DacrtOptions leaves them 0, chosen by measurement
// (docs/benchmarks.md): a leaf costs the CPU one test per pair, while on lavapipe a
// partition costs several times a leaf's test per element (docs/gpu.md), so the gpu stops
// splitting earlier.
constexpr std::uint32_t kCpuLeafLimit = 8;
constexpr std::uint32_t kGpuLeafLimit = 64;

struct DacrtOptions {
    std::uint32_t rayLimit = 0;    // a node with fewer live rays is a leaf; 0: the backend's default
    std::uint32_t triLimit = 0;    // a node with fewer triangles is a leaf; 0: the backend's default
    std::uint32_t maxDepth = 48;   // guards against coincident triangles that never separate
    SplitMethod split = SplitMethod::SpatialMedian;
    Intersector intersector = Intersector::Watertight;
    TriangleFilter triangleFilter = TriangleFilter::Bounds;
    Precision precision = Precision::F32;

    // These options with the leaf limits of `backend` filled in where they are 0.
    DacrtOptions resolvedFor(Backend backend) const {
        DacrtOptions o = *this;
        const std::uint32_t limit = backend == Backend::Gpu ? kGpuLeafLimit : kCpuLeafLimit;
        if (o.rayLimit == 0) o.rayLimit = limit;
        if (o.triLimit == 0) o.triLimit = limit;
        return o;
    }

    bool exactDefaults() const {
        return intersector == Intersector::Watertight && triangleFilter == TriangleFilter::Bounds &&
               precision == Precision::F32;
    }
};

struct TraceOptions {
    Backend backend = Backend::Cpu;
    unsigned regions = 0;   // cpu: sub-scenes; 0 means one per thread (docs/cpu-reference.md)
    unsigned threads = 0;   // 0 means every core
    DivisionAxis axis = DivisionAxis::Best;
    DacrtOptions dacrt;
};

// Everything a tracer reads, prepared once per frame and shared by every backend.
struct FrameGeometry {
    const std::vector<Triangle>* triangles = nullptr;
    const std::vector<Bounds>* triangleBounds = nullptr;
    const std::vector<Ray>* rays = nullptr;
    Box sceneBox;          // exact bounds of the triangles
    glm::vec3 rayOrigin{};  // every ray starts here (primary rays)
    float margin = 0.0f;    // filter widening, see filterMargin()
};

// Widening applied to every box before a ray or triangle filter, so that rounding in the
// intersection test can never move a hit out of the cells that test it. See
// docs/correctness.md for the derivation: 64 units in the last place of the largest
// coordinate magnitude among the scene bounds and the ray origin.
float filterMargin(const Box& sceneBox, const glm::vec3& rayOrigin);

// The frame every tracer reads: the arrays (which must outlive it), the scene box, the rays'
// common origin (the first ray's) and the filter margin derived from both.
FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox);

struct Counters {
    std::uint64_t rayBoxTests = 0;
    std::uint64_t rayTriangleTests = 0;
    std::uint64_t leaves = 0;
    std::uint64_t raysRetired = 0;       // finished by the parallel scheme without a further hit
    std::uint64_t raysCulled = 0;        // missed the scene box
    std::uint64_t terminatedStep1 = 0;   // for cpu-seq: every terminated ray
    std::vector<std::uint64_t> terminatedPerRound;  // transfer rounds in execution order
    std::vector<std::string> roundNames;
    std::uint64_t transferWorkItems = 0;
    std::uint64_t transferWorkItemsSkipped = 0;

    void add(const Counters& o) {
        rayBoxTests += o.rayBoxTests;
        rayTriangleTests += o.rayTriangleTests;
        leaves += o.leaves;
        raysRetired += o.raysRetired;
    }
};

struct MemoryPlan {
    std::vector<std::pair<std::string, std::uint64_t>> buffers;
    void add(const std::string& name, std::uint64_t bytes) { buffers.emplace_back(name, bytes); }
    std::uint64_t total() const {
        std::uint64_t t = 0;
        for (const auto& b : buffers) t += b.second;
        return t;
    }
    std::string describe() const;
};

// What only the gpu backend reports.
struct GpuReport {
    std::string device;
    std::string driver;
    std::uint32_t workgroupSize = 0;
    std::uint32_t subgroupSize = 0;
    std::uint32_t rayGroups = 0;       // work items per region and round (groupRegions)
    std::vector<std::pair<std::string, double>> dispatchMs;  // GPU timestamps, per dispatch
    std::uint32_t dispatches = 0;
    std::uint32_t workItemsRun = 0;
    std::uint32_t workItemsEmpty = 0;
    std::uint32_t slices = 0;          // work item slices (more than work items: continuations)
    std::uint64_t raysFinished = 0;    // rays ended by a hit or retired, over all steps
    std::uint32_t validationErrors = 0;
};

struct TraceResult {
    std::vector<Hit> hits;   // one per ray
    Counters counters;
    MemoryPlan memory;
    std::vector<std::pair<std::string, double>> phaseMs;  // backend-specific parts of the trace
    std::vector<double> step1RegionMs;   // cpu: each region's Step 1 work item, for load balance
    unsigned threads = 1;
    unsigned regions = 1;
    int axis = -1;           // division axis used (cpu, gpu), -1 if none
    std::optional<GpuReport> gpu;
};

}  // namespace dacrt
