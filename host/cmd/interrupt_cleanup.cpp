#include "cmd/interrupt_cleanup.hpp"

#include <csignal>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include <pthread.h>
#include <unistd.h>

namespace dacrt {
namespace {

std::mutex& pendingMutex() {
    static std::mutex m;
    return m;
}

std::multiset<std::string>& pendingFiles() {
    static std::multiset<std::string> files;
    return files;
}

// The signal thread: sigwait makes the signal an ordinary event here, so the cleanup may take a
// lock and print, which a signal handler may not.
void waitForStopSignal(sigset_t signals) {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    // Held until _exit: no temporary is registered, or its guard ended, while they are removed.
    pendingMutex().lock();
    std::string removed;
    for (const std::string& path : pendingFiles())
        if (::unlink(path.c_str()) == 0) removed += (removed.empty() ? " " : ", ") + path;
    std::cerr << "\ndacrt: stopped by " << (signal == SIGTERM ? "SIGTERM" : "SIGINT") << " (exit " << 128 + signal
              << ")"
              << (removed.empty() ? std::string("; no file was being written") : "; removed the unfinished" + removed)
              << "\n"
              << std::flush;
    ::_exit(128 + signal);
}

}  // namespace

void stopCleanlyOnSignals() {
    static std::once_flag once;
    std::call_once(once, [] {
        sigset_t signals;
        sigemptyset(&signals);
        sigaddset(&signals, SIGTERM);
        sigaddset(&signals, SIGINT);
        pthread_sigmask(SIG_BLOCK, &signals, nullptr);
        std::thread(waitForStopSignal, signals).detach();
    });
}

PendingTemporary::PendingTemporary(std::string path) : path_(std::move(path)) {
    const std::lock_guard<std::mutex> lock(pendingMutex());
    pendingFiles().insert(path_);
}

PendingTemporary::~PendingTemporary() {
    const std::lock_guard<std::mutex> lock(pendingMutex());
    pendingFiles().erase(pendingFiles().find(path_));
}

}  // namespace dacrt
