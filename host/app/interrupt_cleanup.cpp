#include "app/interrupt_cleanup.hpp"

#include <csignal>
#include <iostream>
#include <mutex>
#include <thread>

#include <pthread.h>
#include <unistd.h>

#include "core/atomic_file.hpp"

namespace dacrt {
namespace {

// The signal thread: sigwait makes the signal an ordinary event here, so the cleanup may take a
// lock and print, which a signal handler may not.
void waitForStopSignal(sigset_t signals) {
    int signal = 0;
    while (sigwait(&signals, &signal) != 0) {
    }
    std::string removed;
    for (const std::string& path : removeUnfinishedTemporariesForExit()) removed += (removed.empty() ? " " : ", ") + path;
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

}  // namespace dacrt
