#pragma once
// What a caller chooses for a trace: the backend, the DACRT options and the frame's skips.
// Plain data, shared by the library's public API and its internals (host/cpu/options.hpp adds
// the names the command line gives them).
#include <cstdint>

namespace dacrt {

enum class Backend { Brute, CpuSeq, Cpu, Gpu, Embree, RayQuery };
// gpu and rayquery run on a Vulkan device.
constexpr bool runsOnVulkan(Backend b) { return b == Backend::Gpu || b == Backend::RayQuery; }
// embree and rayquery are the peers: they build their own hierarchy and take no DACRT options.
constexpr bool isPeer(Backend b) { return b == Backend::Embree || b == Backend::RayQuery; }
enum class SplitMethod { SpatialMedian, CentroidMean, SampledMean };
// What makes a DACRT node a leaf. Limits: fewer rays or triangles than the leaf limits.
// RaySampling (Nabata et al. 2013, cpu only): above the limits too, wherever a fixed sample of
// the node's rays and triangles estimates a leaf cheaper than filtering them into children;
// it also picks the split among the split method's position and the axis's quarter points.
enum class SplitCost { Limits, RaySampling };
// How the cpu backends trace a secondary pass's rays (docs/cpu-reference.md): Slots, as made,
// pixel by pixel, in one DACRT; Octant, grouped by the signs of their directions, in one;
// OctantCalls, each octant's group in a DACRT of its own, its rays' signs all agreeing;
// Batches, as made, in DACRTs of at most kPassBatchRays rays each. Every grouping gives the
// same visibility: it changes speed only.
enum class RayGrouping { Slots, Octant, OctantCalls, Batches };
// How the cpu backends trace a frame's secondary passes (docs/secondary-rays.md): Apart, each
// pass in its own traces after its own pass cull; Together, every pass's rays merged pixel by
// pixel into the same traces, which then divide the triangles once for all of them; Auto,
// together where the passes make fewer rays than the scene has triangles (the triangles'
// division is then most of a pass's cost), apart elsewhere (a shadow pass's own cull then
// pays) and under the octant groupings. Both give the same visibility: it changes speed only.
enum class PassTracing { Auto, Apart, Together };
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

// Leaf limits of each backend when DacrtOptions leaves them 0, chosen by measurement
// (docs/benchmarks.md): a leaf costs the CPU one test per pair, and the SIMD leaf of the
// default options tests a vector of triangles at once, so it takes more triangles (and,
// with packets above it, more rays) before a split pays; on lavapipe a partition costs
// several times a leaf's test per element (docs/gpu.md), so the gpu stops splitting
// earlier still.
constexpr std::uint32_t kCpuLeafLimit = 8;
constexpr std::uint32_t kCpuSimdRayLimit = 16;
constexpr std::uint32_t kCpuSimdTriangleLimit = 64;
// ... and for a secondary pass traced alone (cpu/secondary_rays.hpp, passDacrtOptions): rays
// that start on the surfaces in a cell, so that a split divides them with its triangles (the
// Bunny's occlusion pass about 9% faster than at 64 and the room's shadow pass 4%, the others
// as fast; docs/benchmarks.md).
constexpr std::uint32_t kCpuSimdSecondaryTriangleLimit = 48;
constexpr std::uint32_t kGpuLeafLimit = 64;
constexpr std::uint32_t kPacketFlushDefault = 16;
// RayGrouping::Batches: the most rays one DACRT of a secondary pass takes, this many or
// kPassBatchRaysPerTriangle per triangle of the scene where that is more. A pass of more is
// cut into equal runs of slots, each traced on its own: a trace's rays, ids and scratch then
// stay nearer the caches, while every trace filters the triangles again (measured:
// docs/benchmarks.md, "Secondary rays grouped").
constexpr std::uint32_t kPassBatchRays = 65536;
constexpr std::uint32_t kPassBatchRaysPerTriangle = 8;

struct DacrtOptions {
    std::uint32_t rayLimit = 0;    // a node with fewer live rays is a leaf; 0: the backend's default
    std::uint32_t triLimit = 0;    // a node with fewer triangles is a leaf; 0: the backend's default
    std::uint32_t maxDepth = 48;   // guards against coincident triangles that never separate
    SplitMethod split = SplitMethod::SpatialMedian;
    SplitCost splitCost = SplitCost::Limits;
    Intersector intersector = Intersector::Watertight;
    TriangleFilter triangleFilter = TriangleFilter::Bounds;
    Precision precision = Precision::F32;
    // Ray packets (docs/cpu-reference.md): primary rays filtered 8x8 pixels at a time high in
    // the recursion, one by one below; the SIMD path of rays that share their start only.
    bool packets = true;
    std::uint32_t packetFlush = 0;  // a node with fewer packets goes on ray by ray; 0: the default
    // Tight node boxes (docs/cpu-reference.md, docs/gpu.md): on the DACRT backends, a node whose
    // rays number at least twice its triangles traces inside the box of their bounds rather than
    // its whole cell.
    bool tightBoxes = true;
    // Secondary passes on the cpu backends: batches by default (the room's lit frame 0.74x of
    // slots, the Bunny's and the Dragon's passes one batch: docs/benchmarks.md).
    RayGrouping rayGrouping = RayGrouping::Batches;
    PassTracing passTracing = PassTracing::Auto;

    // These options with the leaf limits of `backend` filled in where they are 0.
    DacrtOptions resolvedFor(Backend backend) const {
        DacrtOptions o = *this;
        const std::uint32_t limit = backend == Backend::Gpu ? kGpuLeafLimit : kCpuLeafLimit;
        const bool simd = backend != Backend::Gpu && exactDefaults();
        if (o.rayLimit == 0) o.rayLimit = simd ? kCpuSimdRayLimit : limit;
        if (o.triLimit == 0) o.triLimit = simd ? kCpuSimdTriangleLimit : limit;
        if (o.packetFlush == 0) o.packetFlush = kPacketFlushDefault;
        return o;
    }

    bool exactDefaults() const {
        return intersector == Intersector::Watertight && triangleFilter == TriangleFilter::Bounds &&
               precision == Precision::F32;
    }
};

// The frame's skips (docs/skips.md), each exact by construction, each on unless turned off
// (--no-skip): they change speed only.
enum class Skip { BackFaces, Frustum, Uploads, SubScenes, PassRays };
struct SkipSwitches {
    bool backFaces = true;  // single-sided triangles facing away from the rays' shared origin (or
                            // a secondary pass's shared direction, or toward its shared end)
    bool frustum = true;    // triangles outside the camera's view frustum
    bool uploads = true;    // gpu: triangle buffers kept on the device while the triangles do not change
    bool subScenes = true;  // cpu: one sequential DACRT instead of sub-scenes for frames too small to pay
                            // for a division (kSequentialBelowRays), unless --regions is given
    bool passRays = true;   // secondary passes: triangles that no segment of the pass's rays comes near
    bool operator==(const SkipSwitches&) const = default;
};

struct TraceOptions {
    Backend backend = Backend::Cpu;
    SkipSwitches skips;
    unsigned regions = 0;   // cpu: sub-scenes; 0 means one per thread (docs/cpu-reference.md)
    unsigned threads = 0;   // 0 means every core
    DivisionAxis axis = DivisionAxis::Best;
    DacrtOptions dacrt;
};

// The threads a trace with these options runs on: 1 for cpu-seq, else `threads` or every core.
unsigned traceThreads(const TraceOptions& options);

}  // namespace dacrt
