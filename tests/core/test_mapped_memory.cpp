// Mapping an array's pages ahead is advice to the system: whatever it grants or refuses, and
// whether the pages were mapped already (memory freed and allocated again) or not, the
// array's contents and size are what the same calls without it give.
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "core/mapped_memory.hpp"

namespace dacrt {
namespace {

constexpr std::size_t kMiB = std::size_t(1) << 20;

TEST(MappedMemory, MappingKeepsTheContentsWhetherThePagesWereMappedOrNot) {
    // 6 MiB: past a huge page, so the advice is given. Written, then mapped (its pages are
    // mapped already), then mapped again over a range that starts and ends inside pages.
    std::vector<std::uint32_t> v(6 * kMiB / 4);
    std::iota(v.begin(), v.end(), 7u);
    mapForWriting(v.data(), v.size() * 4);
    for (std::size_t i = 0; i < v.size(); i += 4099) ASSERT_EQ(v[i], std::uint32_t(i + 7)) << i;
    mapForWriting(v.data() + 5, v.size() * 4 - 20);  // a range that starts and ends inside pages
    for (std::size_t i = 0; i < v.size(); i += 4099) ASSERT_EQ(v[i], std::uint32_t(i + 7)) << i;
    EXPECT_EQ(v.front(), 7u);
    EXPECT_EQ(v.back(), std::uint32_t(v.size() + 6));
}

TEST(MappedMemory, ReserveAndResizeKeepTheElementsAndZeroTheNewOnes) {
    std::vector<std::uint64_t> v = {1, 2, 3};
    reserveMapped(v, 3 * kMiB);  // fresh memory: advised and populated
    ASSERT_GE(v.capacity(), 3 * kMiB);
    EXPECT_EQ(v, (std::vector<std::uint64_t>{1, 2, 3}));
    resizeMapped(v, 3 * kMiB);
    ASSERT_EQ(v.size(), 3 * kMiB);
    EXPECT_EQ(v[2], 3u);
    for (std::size_t i = 3; i < v.size(); i += 1021) ASSERT_EQ(v[i], 0u) << i;
    EXPECT_EQ(v.back(), 0u);
    v.assign(v.size(), 9u);
    resizeMapped(v, 4 * kMiB);  // grows: new memory, the old elements copied
    EXPECT_EQ(v[3 * kMiB - 1], 9u);
    EXPECT_EQ(v[3 * kMiB], 0u);
    resizeMapped(v, 10);  // shrinks: no mapping, the first elements kept
    EXPECT_EQ(v, std::vector<std::uint64_t>(10, 9u));
}

// Every element, on a pool of 2 and on the calling thread, over sizes that end inside a chunk
// of the fill, on one, and with none; mappedArray's elements are value-initialized.
TEST(MappedMemory, ArraysAreFilledWithTheirValueFreshOrReused) {
    ThreadPool pool(2);
    struct Slot {
        float t;
        std::uint32_t id;
        float u, v;
    };
    const Slot value{0.5f, 0xFFFFFFFEu, 0.25f, 0.125f};
    for (ThreadPool* on : {static_cast<ThreadPool*>(nullptr), &pool})
        for (int round = 0; round < 3; ++round) {  // later rounds may reuse the memory freed before
            for (const std::size_t n : {std::size_t(0), std::size_t(1), kFillChunk, 3 * kFillChunk + 17, 5 * kMiB}) {
                const std::vector<Slot> a = filledArray(n, value, on);
                ASSERT_EQ(a.size(), n);
                const auto differs = std::count_if(a.begin(), a.end(), [&](const Slot& e) {
                    return !(e.t == value.t && e.id == value.id && e.u == value.u && e.v == value.v);
                });
                EXPECT_EQ(differs, 0) << "of " << n << (on ? " on a pool" : "");
            }
            // Value-initialized, in memory that held other values (a small array reuses the heap's
            // freed block; a large one is mapped fresh).
            for (const std::size_t n : {std::size_t(1000), 5 * kMiB}) {
                { const std::vector<float> before(n, 2.5f); }
                const std::vector<float> zeros = mappedArray<float>(n);
                ASSERT_EQ(zeros.size(), n);
                EXPECT_EQ(std::count(zeros.begin(), zeros.end(), 0.0f), std::ptrdiff_t(n));
            }
        }
    EXPECT_TRUE(mappedArray<int>(0).empty());
    mapForWriting(nullptr, 8 * kMiB);  // nothing to map
}

}  // namespace
}  // namespace dacrt
