// The thread pool: every index once, on workers of the pool, after idle spells too. A loop after
// an idle spell steers the sleeping workers off the caller's CPU for their wake only: it counts
// as a steer, and each worker runs the loop's body with its own CPUs allowed again. A pool whose
// workers have one CPU never steers.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include "core/thread_pool.hpp"

using namespace dacrt;

namespace {

cpu_set_t ownCpus() {
    cpu_set_t set;
    CPU_ZERO(&set);
    pthread_getaffinity_np(pthread_self(), sizeof(set), &set);
    return set;
}

// Runs count indices on the pool: every index must come once, on a worker id of the pool, and
// every call's thread must be allowed exactly `expected`.
void expectLoopOn(ThreadPool& pool, std::size_t count, const cpu_set_t& expected) {
    std::vector<std::atomic<int>> seen(count);
    std::vector<char> sameCpus(count, 0);
    pool.parallelFor(count, [&](std::size_t i, unsigned worker) {
        EXPECT_LT(worker, pool.size());
        ++seen[i];
        const cpu_set_t cpus = ownCpus();
        sameCpus[i] = CPU_EQUAL(&cpus, &expected) ? 1 : 0;
        // Long enough that every worker takes some of the indices.
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
    for (std::size_t i = 0; i < count; ++i) {
        EXPECT_EQ(seen[i].load(), 1) << "index " << i;
        EXPECT_TRUE(sameCpus[i]) << "index " << i << " ran on a thread not allowed its pool's CPUs";
    }
}

}  // namespace

TEST(ThreadPool, AfterIdleSpellsEveryIndexRunsOnceWithThePoolsCpusAllowed) {
    const cpu_set_t process = ownCpus();
    if (CPU_COUNT(&process) < 2) GTEST_SKIP() << "one CPU allowed here: no other CPU to steer a worker to";
    ThreadPool pool(4);
    for (int round = 0; round < 3; ++round) {
        const std::uint64_t before = pool.steers();
        // Longer than the spell after which a loop steers its workers (thread_pool.cpp).
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        expectLoopOn(pool, 64, process);
        EXPECT_EQ(pool.steers(), before + 1) << "round " << round;
        expectLoopOn(pool, 64, process);  // back to back
    }
}

TEST(ThreadPool, APoolWhoseWorkersHaveOneCpuNeverSteers) {
    const cpu_set_t before = ownCpus();
    const int here = sched_getcpu();
    ASSERT_GE(here, 0);
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(here, &one);
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(one), &one), 0);
    {
        ThreadPool pool(3);  // its workers inherit the one CPU
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        expectLoopOn(pool, 32, one);
        EXPECT_EQ(pool.steers(), 0u);
    }
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(before), &before), 0);
}
