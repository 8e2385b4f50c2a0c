#include "core/process_memory.hpp"

#include <fstream>
#include <sstream>
#include <string>

namespace dacrt {

std::optional<ResidentMemory> residentMemory() {
    std::ifstream status("/proc/self/status");
    if (!status) return std::nullopt;
    ResidentMemory m;
    bool current = false, peak = false;
    for (std::string line; std::getline(status, line);) {
        // "VmHWM:     123456 kB"
        std::istringstream fields(line);
        std::string key, unit;
        std::uint64_t kib = 0;
        if (!(fields >> key >> kib >> unit) || unit != "kB") continue;
        if (key == "VmRSS:") current = true, m.current = kib * 1024;
        if (key == "VmHWM:") peak = true, m.peak = kib * 1024;
    }
    if (!current || !peak) return std::nullopt;
    return m;
}

}  // namespace dacrt
