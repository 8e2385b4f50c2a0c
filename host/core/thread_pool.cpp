#include "core/thread_pool.hpp"

#include <cstring>
#include <exception>

#include <pthread.h>
#include <sched.h>

namespace dacrt {
namespace {

// How long the workers may have slept before a loop steers them off the caller's CPU: the
// slowdown was measured after 30 ms and not after 10 (docs/benchmarks.md).
constexpr auto kIdleSpell = std::chrono::milliseconds(5);

}  // namespace

ThreadPool::ThreadPool(unsigned threads) : steered_(std::max(threads, 1u)) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    if (sched_getaffinity(0, sizeof(allowed), &allowed) == 0 && CPU_COUNT(&allowed) > 1) {
        allowedCpus_.resize(sizeof(allowed));
        std::memcpy(allowedCpus_.data(), &allowed, sizeof(allowed));
    }
    lastLoopEnd_ = std::chrono::steady_clock::now();
    for (std::atomic<bool>& s : steered_) s.store(false);
    for (unsigned w = 1; w < std::max(threads, 1u); ++w) workers_.emplace_back([this, w] { workerLoop(w); });
}

// A loop after an idle spell: a worker that slept long may be woken onto the caller's own CPU,
// and on a VM whose other vCPUs went idle the guest's scheduler left it there for tens of
// milliseconds, the loop running on one core (docs/benchmarks.md, "Frames after a pause").
// Each sleeping worker is allowed every CPU but the caller's for this wake; it takes back the
// pool's CPUs once running (workerLoop).
void ThreadPool::steerWorkersAwayFromCaller() {
    if (allowedCpus_.empty()) return;
    const int here = sched_getcpu();
    cpu_set_t away;
    std::memcpy(&away, allowedCpus_.data(), sizeof(away));
    if (here < 0 || !CPU_ISSET(here, &away)) return;
    CPU_CLR(here, &away);
    for (std::size_t w = 0; w < workers_.size(); ++w)
        if (pthread_setaffinity_np(workers_[w].native_handle(), sizeof(away), &away) == 0) steered_[w + 1] = true;
}

ThreadPool::~ThreadPool() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
}

void ThreadPool::drain(unsigned worker) {
    for (std::size_t i = next_.fetch_add(1); i < count_; i = next_.fetch_add(1)) (*body_)(i, worker);
}

void ThreadPool::workerLoop(unsigned worker) {
    unsigned long seen = 0;
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
            if (stopping_) return;
            seen = generation_;
        }
        if (steered_[worker].exchange(false)) {
            cpu_set_t allowed;
            std::memcpy(&allowed, allowedCpus_.data(), sizeof(allowed));
            pthread_setaffinity_np(pthread_self(), sizeof(allowed), &allowed);
        }
        drain(worker);
        std::lock_guard<std::mutex> lock(mutex_);
        if (--busy_ == 0) done_.notify_one();
    }
}

void ThreadPool::parallelFor(std::size_t count, const std::function<void(std::size_t, unsigned)>& body) {
    if (count == 0) return;
    if (workers_.empty() || count == 1) {
        for (std::size_t i = 0; i < count; ++i) body(i, 0);
        return;
    }
    if (std::chrono::steady_clock::now() - lastLoopEnd_ > kIdleSpell) steerWorkersAwayFromCaller();
    {
        std::lock_guard<std::mutex> lock(mutex_);
        body_ = &body;
        count_ = count;
        next_.store(0);
        busy_ = unsigned(workers_.size());
        ++generation_;
    }
    wake_.notify_all();
    drain(0);
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
    body_ = nullptr;
    lastLoopEnd_ = std::chrono::steady_clock::now();
}

void ThreadPool::parallelForRethrowing(std::size_t count, const std::function<void(std::size_t, unsigned)>& body) {
    std::exception_ptr failure;
    std::mutex failureMutex;
    parallelFor(count, [&](std::size_t i, unsigned worker) {
        try {
            body(i, worker);
        } catch (...) {
            const std::lock_guard<std::mutex> lock(failureMutex);
            if (!failure) failure = std::current_exception();
        }
    });
    if (failure) std::rethrow_exception(failure);
}

}  // namespace dacrt
