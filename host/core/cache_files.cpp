#include "core/cache_files.hpp"

#include <cstdlib>
#include <iomanip>
#include <sstream>

namespace dacrt {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t seed) {
    std::uint64_t h = seed;
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

std::string hex16(std::uint64_t h) {
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << h;
    return hex.str();
}

std::string defaultCacheDir() {
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/dacrt";
    if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/dacrt";
    return ".dacrt-cache";
}

}  // namespace dacrt
