#include "core/thread_pool.hpp"

#include <cstring>
#include <exception>

#include <pthread.h>
#include <sched.h>

namespace dacrt {
namespace {

// How long the workers may have slept before a loop steers them off the caller's CPU: the
// slowdown was measured after sleeps of 30 ms and more, not after 10 (docs/benchmarks.md); a
// steer costs the caller two system calls a worker, so it is kept to loops after such spells.
constexpr auto kIdleSpell = std::chrono::milliseconds(5);

}  // namespace

ThreadPool::ThreadPool(unsigned threads)
    : lastLoopEnd_(std::chrono::steady_clock::now()),
      cpusBeforeSteer_(std::max(threads, 1u), std::vector<unsigned char>(sizeof(cpu_set_t))),
      steered_(std::max(threads, 1u)) {
    for (unsigned w = 1; w < std::max(threads, 1u); ++w) workers_.emplace_back([this, w] { workerLoop(w); });
}

// A loop after an idle spell: a worker that slept long may be woken onto the caller's own CPU,
// and on a VM whose other vCPUs went idle the guest's scheduler left it there for tens of
// milliseconds, the loop running on one core (docs/benchmarks.md, "Frames after a pause").
// Each sleeping worker is allowed the CPUs it could run on, but the caller's, for this wake; it
// takes those CPUs back once running (workerLoop). A worker with no other CPU is left alone, and
// so is one whose earlier restore failed (it is still flagged, and retries at this wake).
void ThreadPool::steerWorkersAwayFromCaller() {
    const int here = sched_getcpu();
    if (here < 0) return;
    bool steered = false;
    for (std::size_t w = 0; w < workers_.size(); ++w) {
        if (steered_[w + 1]) continue;
        cpu_set_t before;
        CPU_ZERO(&before);
        if (pthread_getaffinity_np(workers_[w].native_handle(), sizeof(before), &before) != 0) continue;
        cpu_set_t away = before;
        CPU_CLR(here, &away);
        if (CPU_COUNT(&away) == 0 || CPU_EQUAL(&away, &before)) continue;
        std::memcpy(cpusBeforeSteer_[w + 1].data(), &before, sizeof(before));
        if (pthread_setaffinity_np(workers_[w].native_handle(), sizeof(away), &away) != 0) continue;
        steered_[w + 1] = true;
        steered = true;
    }
    if (steered) ++steers_;
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
        if (steered_[worker]) {
            cpu_set_t before;
            std::memcpy(&before, cpusBeforeSteer_[worker].data(), sizeof(before));
            if (pthread_setaffinity_np(pthread_self(), sizeof(before), &before) == 0) steered_[worker] = false;
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
