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
    const char* name = signal == SIGTERM ? "SIGTERM" : signal == SIGHUP ? "SIGHUP" : "SIGINT";
    std::cerr << "\ndacrt: stopped by " << name << " (exit " << 128 + signal
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
        sigaddset(&signals, SIGHUP);  // the terminal closed, or a job scheduler's stop
        pthread_sigmask(SIG_BLOCK, &signals, nullptr);
        // A FIFO output whose reader went away: the write fails with EPIPE and the command
        // reports it, removing the frame's other outputs, instead of dying without a word.
        std::signal(SIGPIPE, SIG_IGN);
        // The same for a file size limit (ulimit -f): the write fails with EFBIG and is reported.
        std::signal(SIGXFSZ, SIG_IGN);
        std::thread(waitForStopSignal, signals).detach();
    });
}

}  // namespace dacrt
