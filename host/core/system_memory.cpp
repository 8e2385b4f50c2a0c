#include "core/system_memory.hpp"

#include <limits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <unistd.h>

#include "core/errors.hpp"

namespace dacrt {

std::uint64_t physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? std::uint64_t(pages) * std::uint64_t(pageSize) : 0;
}

void checkFitsInMemory(const std::string& what, std::uint64_t bytes, const std::string& advice) {
    const std::uint64_t limit = physicalMemoryBytes();
    if (limit && bytes > limit)
        throw InputError(what + " needs " + std::to_string(bytes) + " bytes but this machine has " + std::to_string(limit) +
                         " bytes of memory (over by " + std::to_string(bytes - limit) + " bytes); " + advice);
}

void reuseFreedMemory() {
#if defined(__GLIBC__)
    mallopt(M_MMAP_THRESHOLD, 1 << 30);
    mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
#endif
}

}  // namespace dacrt
