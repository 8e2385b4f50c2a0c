// The portable random numbers behind the generated cases: the same seed must give the same
// numbers with every compiler and standard library.
#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "core/random.hpp"

namespace dacrt {
namespace {

TEST(Random, IsMt19937_64WithItsStandardSequence) {
    // The standard fixes the 10000th output of a default-seeded std::mt19937_64.
    std::mt19937_64 engine;
    engine.discard(9999);
    EXPECT_EQ(engine(), 9981545732273789042ull);
    // uniform() keeps the top 53 bits of each output.
    std::mt19937_64 reference(42);
    Random random(42);
    for (int i = 0; i < 100; ++i) EXPECT_EQ(random.uniform(), double(reference() >> 11) * 0x1p-53);
}

TEST(Random, RangesHold) {
    Random random(7);
    for (int i = 0; i < 10000; ++i) {
        const double u = random.uniform(-2.0, 3.0);
        EXPECT_GE(u, -2.0);
        EXPECT_LT(u, 3.0);
        EXPECT_LT(random.index(7), 7u);
        const glm::vec3 v = random.vec3(-1.0f, 1.0f);
        EXPECT_TRUE(v.x >= -1.0f && v.x <= 1.0f && v.y >= -1.0f && v.y <= 1.0f && v.z >= -1.0f && v.z <= 1.0f);
        EXPECT_NEAR(glm::length(random.onSphere()), 1.0, 1e-12);
    }
}

TEST(Random, ShuffleIsAPermutationAndDependsOnTheSeed) {
    std::vector<int> a(100), b(100);
    std::iota(a.begin(), a.end(), 0);
    std::iota(b.begin(), b.end(), 0);
    Random one(1), two(2);
    one.shuffle(a);
    two.shuffle(b);
    EXPECT_NE(a, b);
    std::vector<int> sorted = a;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < 100; ++i) EXPECT_EQ(sorted[std::size_t(i)], i);
    std::vector<int> again(100);
    std::iota(again.begin(), again.end(), 0);
    Random oneAgain(1);
    oneAgain.shuffle(again);
    EXPECT_EQ(a, again);
}

}  // namespace
}  // namespace dacrt
