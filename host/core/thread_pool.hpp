#pragma once
// A fixed set of worker threads running one parallel loop at a time. The calling thread
// takes part, so a pool of size 1 runs everything inline.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace dacrt {

class ThreadPool {
public:
    explicit ThreadPool(unsigned threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    unsigned size() const { return unsigned(workers_.size()) + 1; }
    // How many loops so far steered their workers off the caller's CPU (after an idle spell).
    std::uint64_t steers() const { return steers_; }

    // Calls body(index, worker) for every index in [0, count), handing out indices one at a
    // time (dynamic balance); worker is in [0, size()). Returns when all calls are done.
    void parallelFor(std::size_t count, const std::function<void(std::size_t, unsigned)>& body);
    // parallelFor for a body that may throw: each call's exception is caught on its thread (a
    // pool's thread must not throw), and the first one is rethrown here once all calls are done.
    void parallelForRethrowing(std::size_t count, const std::function<void(std::size_t, unsigned)>& body);

private:
    void workerLoop(unsigned worker);
    void drain(unsigned worker);
    void steerWorkersAwayFromCaller();

    std::vector<std::thread> workers_;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable done_;
    const std::function<void(std::size_t, unsigned)>* body_ = nullptr;
    std::size_t count_ = 0;
    std::atomic<std::size_t> next_{0};
    unsigned busy_ = 0;
    unsigned long generation_ = 0;
    bool stopping_ = false;
    // When the last loop ended (read and written by the one thread that calls parallelFor at a
    // time), and for each worker steered off the caller's CPU for its next wake, the CPUs it
    // could run on before, which it takes back once running (a cpu_set_t's bytes).
    std::chrono::steady_clock::time_point lastLoopEnd_;
    std::vector<std::vector<unsigned char>> cpusBeforeSteer_;
    std::vector<std::atomic<bool>> steered_;
    std::uint64_t steers_ = 0;
};

// Elements per chunk of a frame's passes over its rays, hits or triangles (1 MiB of 64-byte
// rays): enough work per hand-out, and chunks enough to share among the threads.
constexpr std::size_t kFrameScanChunk = 16384;

// Calls body(chunk, begin, end) for the ranges [begin, end) of at most `chunk` consecutive
// indices that cover [0, n), on the pool (in order on the calling thread without one): for a
// frame's passes over its rays or hits, which one thread would make serial.
template <typename Body>
void forEachChunk(std::size_t n, std::size_t chunk, ThreadPool* pool, Body&& body) {
    const std::size_t chunks = (n + chunk - 1) / chunk;
    const auto run = [&](std::size_t c, unsigned) { body(c, c * chunk, std::min(n, (c + 1) * chunk)); };
    if (pool) pool->parallelFor(chunks, run);
    else
        for (std::size_t c = 0; c < chunks; ++c) run(c, 0);
}

// Calls visit(i) for every i in [0, n), in chunks of `chunk` on the pool (in order on the
// calling thread without one), each chunk stopping at its first i for which visit returns
// false; returns the least such i, or n when there is none. What a sequential loop that stops
// at its first failure reports, on every thread count.
template <typename Visit>
std::size_t firstFailureInChunks(std::size_t n, std::size_t chunk, ThreadPool* pool, Visit&& visit) {
    std::vector<std::size_t> first((n + chunk - 1) / chunk, n);
    forEachChunk(n, chunk, pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            if (!visit(i)) {
                first[c] = i;
                return;
            }
    });
    for (const std::size_t i : first)
        if (i < n) return i;
    return n;
}

}  // namespace dacrt
