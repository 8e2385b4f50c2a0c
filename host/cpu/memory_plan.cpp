#include "cpu/memory_plan.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace dacrt {
namespace {

std::string readableBytes(std::uint64_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1024.0 && u < 4) v /= 1024.0, ++u;
    char text[32];
    std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.1f %s", v, units[u]);
    return text;
}

}  // namespace

std::string MemoryPlan::describe() const {
    std::size_t width = 5;  // "total"
    for (const auto& b : buffers) width = std::max(width, b.first.size());
    std::ostringstream s;
    auto line = [&](const std::string& name, std::uint64_t bytes) {
        char text[64];
        std::snprintf(text, sizeof text, "%12s  (%llu bytes)", readableBytes(bytes).c_str(), (unsigned long long)bytes);
        s << "  " << name << std::string(width - name.size() + 2, ' ') << text << "\n";
    };
    for (const auto& [name, bytes] : buffers) line(name, bytes);
    line("total", total());
    return s.str();
}

std::string MemoryPlan::describeWork() const {
    std::size_t width = 0;
    for (const WorkLine& w : work) width = std::max(width, w.name.size());
    std::ostringstream s;
    for (const WorkLine& w : work) {
        char count[32];
        std::snprintf(count, sizeof count, "%12llu", (unsigned long long)w.count);
        s << "  " << w.name << std::string(width - w.name.size() + 2, ' ') << count << (w.why.empty() ? "" : "  " + w.why)
          << "\n";
    }
    return s.str();
}

}  // namespace dacrt
