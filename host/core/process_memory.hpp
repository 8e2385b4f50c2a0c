#pragma once
// What this process holds in memory, as the kernel counts it: the figures a memory plan is
// measured against (render --stats, docs/benchmarks.md).
#include <cstdint>
#include <optional>

namespace dacrt {

struct ResidentMemory {
    std::uint64_t current = 0;  // resident now (VmRSS)
    std::uint64_t peak = 0;     // the most resident since the process started (VmHWM)
};

// From /proc/self/status; empty where the system does not say (not Linux, no /proc).
std::optional<ResidentMemory> residentMemory();

}  // namespace dacrt
