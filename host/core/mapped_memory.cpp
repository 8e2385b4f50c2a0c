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

}  // namespace

void mapForWriting(void* data, std::size_t bytes) {
    if (!data || bytes < kHugePage) return;
    const std::uintptr_t page = std::uintptr_t(sysconf(_SC_PAGE_SIZE));
    // Whole pages around the range: madvise changes no contents, so the neighbours' share of
    // the first and last page is unharmed.
    const std::uintptr_t start = std::uintptr_t(data) / page * page;
    const std::uintptr_t end = (std::uintptr_t(data) + bytes + page - 1) / page * page;
    void* const at = reinterpret_cast<void*>(start);
    madvise(at, end - start, MADV_HUGEPAGE);       // advice: refused where THP is off, harmlessly
    madvise(at, end - start, MADV_POPULATE_WRITE);  // refused by kernels before 5.14: first writes map them
}

}  // namespace dacrt
