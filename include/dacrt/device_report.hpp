#pragma once
// What the gpu backend reports of a trace on its device, beyond the counters every backend has.
#include <cstdint>
#include <string>
#include <vector>

namespace dacrt {

struct DeviceReport {
    std::string device;
    std::string driver;
    std::uint32_t workgroupSize = 0;
    std::uint32_t subgroupSize = 0;
    std::uint32_t rayGroups = 0;  // work items per region and round (the discrete profile: on average)
    // The kernel's leaf rule (GpuTuning::leafBalance): a node is a leaf with fewer rays than
    // rayLimit, fewer triangles than triLimit, or its tests under the leaf balance (0: off).
    std::uint32_t rayLimit = 0;
    std::uint32_t triLimit = 0;
    std::uint32_t leafBalance = 0;
    // The kernel's ray packets: how many (0: it traced rays alone, as it does without
    // DacrtOptions::packets, for rays of no image or on a device with a loop limiter), and the
    // packet count below which a node went on ray by ray.
    std::uint32_t packets = 0;
    std::uint32_t packetFlush = 0;
    struct Dispatch {
        std::string name;
        double gpuMs = 0.0;  // the device's timestamps
    };
    std::vector<Dispatch> dispatchTimes;
    std::uint32_t dispatches = 0;
    std::uint32_t workItemsRun = 0;
    std::uint32_t workItemsEmpty = 0;
    std::uint32_t workItemSlices = 0;  // more than work items: continuations
    std::uint64_t raysFinished = 0;    // with a hit or without, over all steps
    std::uint32_t validationErrors = 0;

    // The schedule's dispatches (Step 1, then the transfer rounds: one each, or those on disjoint
    // region slots together, as "toward-low 1 + toward-high 1"), each with its work items
    // and their costs: the loop iterations of the kernel's cost model that a work item spent
    // (docs/gpu.md, "Work items and parallelism"), deterministic for a frame and options.
    struct WorkPass {
        std::string name;
        std::uint32_t workItems = 0;
        std::uint64_t costMax = 0;  // the costliest work item's
        double costMean = 0.0;      // over the dispatch's work items, empty ones (cost 0) included
    };
    std::vector<WorkPass> workPasses;
    std::uint64_t workCost = 0;          // every work item's, summed
    std::uint64_t longestChainCost = 0;  // the costliest chain of work items that wait for each other
    // The parallelism the schedule offers: the work over its longest chain.
    double parallelism() const { return longestChainCost ? double(workCost) / double(longestChainCost) : 0.0; }

    // With GpuTuning::stageClocks: the kernel's time by stage, in the device's subgroup clock
    // ticks summed over the first invocation of every launch (docs/gpu.md, "Where the kernel's
    // time goes"). "launches" holds the others; what it has beyond their sum is the rest of
    // the kernel (the traversal's own steps, empty and finished work items). Empty without.
    struct StageTicks {
        std::string name;  // ray partitions, triangle partitions, leaf tests, stack and slices, waiting, launches
        std::uint64_t ticks = 0;
    };
    std::vector<StageTicks> stageTicks;
};

}  // namespace dacrt
