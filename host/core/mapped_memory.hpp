#pragma once
// Large arrays' pages mapped ahead of their first write. On the project's VM a fresh page
// costs a fault taken through the hypervisor: 512 MiB written into fresh memory takes about
// 1.5 s, the same mapped at once as huge pages about 45 ms (docs/benchmarks.md). A frame's
// set-up writes hundreds of MiB (the flattened triangles, their provenance, their bounds), and
// its trace tens to hundreds more (rays, hits, ids, secondary rays), which a one-frame render
// maps fresh.
#include <algorithm>
#include <cstddef>
#include <type_traits>
#include <vector>

#include "core/thread_pool.hpp"

namespace dacrt {

// Maps the pages of [data, data + bytes) for writing, as transparent huge pages where the
// system allows (madvise MADV_HUGEPAGE, then MADV_POPULATE_WRITE). Leaves the memory's
// contents as they are. Does nothing for ranges under a huge page, for ranges whose pages are
// mapped already (memory freed and allocated again; sampled at the start, middle and end), or
// where the system refuses (the pages are then mapped by the first writes, as without it).
void mapForWriting(void* data, std::size_t bytes);

// Makes `v` hold room for `n` elements (its elements kept) with that room's pages mapped:
// for an array about to be filled to `n`.
template <typename T>
void reserveMapped(std::vector<T>& v, std::size_t n) {
    if (v.capacity() < n) v.reserve(n);
    mapForWriting(v.data(), n * sizeof(T));
}

// `v` resized to `n` elements (new ones value-initialized), its pages mapped first where it
// grows (reserveMapped): for a per-frame array that a later frame reuses.
template <typename T>
void resizeMapped(std::vector<T>& v, std::size_t n) {
    if (v.capacity() < n) reserveMapped(v, n);
    v.resize(n);
}

// A new array of `n` value-initialized elements, its pages mapped at once (reserveMapped).
template <typename T>
std::vector<T> mappedArray(std::size_t n) {
    std::vector<T> v;
    reserveMapped(v, n);
    v.resize(n);
    return v;
}

// Elements per chunk of filledArray's fill on a pool (1 MiB of 16-byte hits).
constexpr std::size_t kFillChunk = 65536;

// A new array of `n` copies of `value`, its pages mapped at once (reserveMapped), filled in
// chunks on the pool (on the calling thread without one). Value-initialized first, then
// filled with std::fill, never resize(n, value): for a 16-byte hit GCC 12 inlined
// resize(n, value) as a loop that rebuilds the value on the stack with narrow stores and
// reloads it with one 16-byte load in every iteration, a load the narrow stores cannot forward
// to. That loop took 7.4 ms for the Bunny's 1.2 million occlusion slots, the zeroing and the
// fill 1.3 ms together (docs/benchmarks.md, "Slot arrays filled without a stall"). Not from a
// task of the same pool (ThreadPool::parallelFor does not nest).
template <typename T>
std::vector<T> filledArray(std::size_t n, const T& value, ThreadPool* pool = nullptr) {
    static_assert(std::is_nothrow_copy_assignable_v<T>, "a pool's task must not throw");
    std::vector<T> v = mappedArray<T>(n);
    forEachChunk(n, kFillChunk, pool, [&](std::size_t, std::size_t begin, std::size_t end) {
        std::fill(v.begin() + std::ptrdiff_t(begin), v.begin() + std::ptrdiff_t(end), value);
    });
    return v;
}

}  // namespace dacrt
