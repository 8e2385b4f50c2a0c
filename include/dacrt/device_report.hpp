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
    std::uint32_t rayGroups = 0;  // work items per region and round
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
};

}  // namespace dacrt
