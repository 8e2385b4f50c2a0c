// The thread pool: every index once, on workers of the pool, after idle spells too; a loop
// after an idle spell steers the sleeping workers off the caller's CPU for their wake only (each
// worker runs the loop's body with the pool's CPUs allowed again), and a pool on one allowed CPU
// does not steer at all.
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

int allowedCpuCount() {
    cpu_set_t set;
    CPU_ZERO(&set);
    pthread_getaffinity_np(pthread_self(), sizeof(set), &set);
    return CPU_COUNT(&set);
}

// Runs count indices on the pool; every index must come once, on a worker id of the pool, and
// each call reports the CPUs its thread may run on.
std::vector<int> loopReportingCpus(ThreadPool& pool, std::size_t count) {
    std::vector<std::atomic<int>> seen(count);
    for (std::atomic<int>& s : seen) s = 0;
    std::vector<int> cpus(count, 0);
    pool.parallelFor(count, [&](std::size_t i, unsigned worker) {
        EXPECT_LT(worker, pool.size());
        ++seen[i];
        cpus[i] = allowedCpuCount();
        // Long enough that every worker takes some of the indices.
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    });
    for (std::size_t i = 0; i < count; ++i) EXPECT_EQ(seen[i].load(), 1) << "index " << i;
    return cpus;
}

}  // namespace

TEST(ThreadPool, AfterIdleSpellsEveryIndexRunsOnceWithThePoolsCpusAllowed) {
    const int processCpus = allowedCpuCount();
    ThreadPool pool(4);
    for (int round = 0; round < 3; ++round) {
        // Longer than the spell after which a loop steers its workers (thread_pool.cpp).
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        for (const int cpus : loopReportingCpus(pool, 64)) EXPECT_EQ(cpus, processCpus) << "round " << round;
        // Back to back: no steering.
        for (const int cpus : loopReportingCpus(pool, 64)) EXPECT_EQ(cpus, processCpus);
    }
}

TEST(ThreadPool, APoolMadeOnOneCpuKeepsItsWorkersThere) {
    cpu_set_t before;
    CPU_ZERO(&before);
    ASSERT_EQ(pthread_getaffinity_np(pthread_self(), sizeof(before), &before), 0);
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(sched_getcpu(), &one);
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(one), &one), 0);
    {
        ThreadPool pool(3);  // its workers inherit the one CPU
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        for (const int cpus : loopReportingCpus(pool, 32)) EXPECT_EQ(cpus, 1);
    }
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(before), &before), 0);
}
