#pragma once
// What every tracer returns: hits, counters, the memory plan and timings.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/shader_layout.hpp"
#include "cpu/memory_plan.hpp"
#include "cpu/phase_times.hpp"

namespace dacrt {

struct Counters {
    std::uint64_t rayBoxTests = 0;
    std::uint64_t packetBoxTests = 0;    // packets of rays tested at once against a box
    std::uint64_t rayTriangleTests = 0;  // a leaf's rays times its triangles, summed
    // Of those, the pairs a leaf's ray groups skipped: no ray of the group can reach the
    // triangle's bounds (simd::intersectBatchInGroups).
    std::uint64_t rayTriangleTestsSkipped = 0;
    std::uint64_t leaves = 0;
    std::uint64_t tightBoxes = 0;  // nodes, of rays or of packets, shrunk to their triangles' box (shrunkBox)
    // A ray is finished once it has its final hit (or none): the parallel scheme finishes rays
    // early, without a further hit, when they cannot reach the next region.
    std::uint64_t raysFinishedWithoutHit = 0;
    std::uint64_t raysCulled = 0;        // missed the scene box
    std::uint64_t finishedStep1 = 0;     // for cpu-seq: every finished ray
    std::vector<std::uint64_t> finishedPerRound;  // transfer rounds in execution order
    std::vector<std::string> roundNames;
    std::uint64_t transferWorkItems = 0;
    std::uint64_t transferWorkItemsSkipped = 0;

    void add(const Counters& o) {
        rayBoxTests += o.rayBoxTests;
        packetBoxTests += o.packetBoxTests;
        rayTriangleTests += o.rayTriangleTests;
        rayTriangleTestsSkipped += o.rayTriangleTestsSkipped;
        leaves += o.leaves;
        tightBoxes += o.tightBoxes;
        raysFinishedWithoutHit += o.raysFinishedWithoutHit;
    }
    // Another trace's counters on top of these (a pass traced in groups): add's, and the rays
    // culled and finished, the transfer work, each transfer round into the round of its name.
    void addTrace(const Counters& o) {
        add(o);
        raysCulled += o.raysCulled;
        finishedStep1 += o.finishedStep1;
        transferWorkItems += o.transferWorkItems;
        transferWorkItemsSkipped += o.transferWorkItemsSkipped;
        for (std::size_t r = 0; r < o.roundNames.size(); ++r) {
            const auto same = std::find(roundNames.begin(), roundNames.end(), o.roundNames[r]);
            if (same == roundNames.end()) {
                roundNames.push_back(o.roundNames[r]);
                finishedPerRound.push_back(o.finishedPerRound[r]);
            } else {
                finishedPerRound[std::size_t(same - roundNames.begin())] += o.finishedPerRound[r];
            }
        }
    }
};

// One dispatch of the gpu's schedule (Step 1, a transfer round, or rounds on disjoint slots
// together: gpu::dispatchedPasses): its work items and their costs, in loop iterations of the
// kernel's cost model (docs/gpu.md).
struct GpuWorkPass {
    std::string name;
    std::uint32_t items = 0;
    std::uint64_t maxCost = 0;
    double meanCost = 0.0;
};

// What only a device backend reports (plain data: the layer that fills it is above this one).
struct GpuReport {
    std::string device;
    std::string driver;
    std::uint32_t workgroupSize = 0;
    std::uint32_t subgroupSize = 0;
    std::uint32_t rayGroups = 0;       // ray groups per region asked for (groupRegions; the discrete profile shares them out by cost)
    std::uint32_t rayLimit = 0;        // the kernel's leaf rule (gpu::kernelLeafRule)
    std::uint32_t triLimit = 0;
    std::uint32_t leafBalance = 0;
    std::uint32_t packets = 0;       // ray packets the kernel traced (0: rays alone; kernelUsesPackets)
    std::uint32_t packetFlush = 0;   // ... and the packet count below which a node went on ray by ray
    std::vector<std::pair<std::string, double>> dispatchMs;  // GPU timestamps, per dispatch
    std::uint32_t dispatches = 0;
    std::uint32_t workItemsRun = 0;
    std::uint32_t workItemsEmpty = 0;
    std::uint32_t slices = 0;          // work item slices (more than work items: continuations)
    std::uint64_t raysFinished = 0;    // rays finished (with a hit or without), over all steps
    std::uint32_t validationErrors = 0;
    std::vector<GpuWorkPass> workPasses;  // gpu: Step 1, then the transfer rounds' dispatches
    std::uint64_t workCost = 0;           // gpu: every work item's cost, summed
    std::uint64_t longestChainCost = 0;   // gpu: the costliest chain of work items that wait for each other
    // gpu with stage clocks: each stage's clock ticks (DACRT_STAGE_* order); empty without.
    std::vector<std::uint64_t> stageTicks;
};

struct TraceResult {
    std::vector<Hit> hits;   // one per ray
    Counters counters;
    MemoryPlan memory;
    PhaseTimes phases;       // the backend's parts of the trace
    std::vector<double> step1RegionMs;   // cpu: each region's Step 1 work item, for load balance
    unsigned threads = 1;
    unsigned regions = 1;
    int axis = -1;           // division axis used (cpu, gpu), -1 if none
    std::optional<GpuReport> gpu;
};

// A hit record meaning "nothing yet" on a whole ray...
inline Hit missHit() { return Hit{kNoHitT, kMissPrim, 0.0f, 0.0f}; }
// ... and on this ray: its segment's end bounds every later test like a hit would.
inline Hit missHit(const Ray& ray) { return Hit{ray.tmax, kMissPrim, 0.0f, 0.0f}; }

}  // namespace dacrt
