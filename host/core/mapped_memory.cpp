#include "core/mapped_memory.hpp"

#include <cstdint>

#include <sys/mman.h>
#include <unistd.h>

namespace dacrt {

namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
#ifndef MADV_POPULATE_WRITE
constexpr int MADV_POPULATE_WRITE = 23;  // Linux 5.14; older headers lack it (older kernels refuse it: EINVAL)
#endif

// Whether the pages at the range's start, middle and end are mapped already: memory the
// process freed and allocates again (reuseFreedMemory) is, and populating it again walks every
// page for nothing (1.5-8 ms per 80 MiB of 4 KiB pages on the project's VM, a frame's arrays
// being allocated anew in every frame). A range only partly mapped takes its faults as without.
bool sampledPagesMapped(std::uintptr_t start, std::uintptr_t end, std::uintptr_t page) {
    for (const std::uintptr_t at : {start, (start + (end - start) / 2) / page * page, end - page}) {
        unsigned char resident = 0;
        if (mincore(reinterpret_cast<void*>(at), page, &resident) != 0 || !(resident & 1)) return false;
    }
    return true;
}

}  // namespace

void mapForWriting(void* data, std::size_t bytes) {
    if (!data || bytes < kHugePage) return;
    const std::uintptr_t page = std::uintptr_t(sysconf(_SC_PAGE_SIZE));
    // Whole pages around the range: madvise changes no contents, so the neighbours' share of
    // the first and last page is unharmed.
    const std::uintptr_t start = std::uintptr_t(data) / page * page;
    const std::uintptr_t end = (std::uintptr_t(data) + bytes + page - 1) / page * page;
    if (sampledPagesMapped(start, end, page)) return;
    void* const at = reinterpret_cast<void*>(start);
    madvise(at, end - start, MADV_HUGEPAGE);       // advice: refused where THP is off, harmlessly
    madvise(at, end - start, MADV_POPULATE_WRITE);  // refused by kernels before 5.14: first writes map them
}

}  // namespace dacrt
