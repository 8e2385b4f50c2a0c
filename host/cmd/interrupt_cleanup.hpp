#pragma once
// A run stopped by SIGTERM or SIGINT (how Slurm and Kubernetes pre-empt, and Ctrl-C) removes the
// temporary file it was writing and exits with 128 + the signal's number, as a shell reports a
// process the signal ended. Files already renamed into place stay: they are complete.
#include <string>

#include "core/atomic_file.hpp"

namespace dacrt {

// Blocks SIGTERM and SIGINT in this thread and every thread it starts from now on, and starts
// one thread that waits for them, removes the pending temporaries and exits. Call it before any
// other thread starts (the worker pools, the Vulkan driver's threads), so that no thread is left
// where the signal's default action would end the process without the cleanup.
void stopCleanlyOnSignals();

// A temporary file being written: removed by the signal thread if a signal comes before the
// guard ends. Harmless once the file is renamed (removing a name that is gone does nothing).
class PendingTemporary {
public:
    explicit PendingTemporary(std::string path);
    ~PendingTemporary();
    PendingTemporary(const PendingTemporary&) = delete;
    PendingTemporary& operator=(const PendingTemporary&) = delete;

private:
    std::string path_;
};

// writeThrough (core/atomic_file.hpp) with the temporary registered for the signal thread:
// write(temporaryPath), then the rename into place; a failure names `path`.
template <typename Write>
void writeOutput(const std::string& path, Write write) {
    AtomicFile file(path);
    const PendingTemporary pending(file.temporaryPath());
    try {
        write(file.temporaryPath());
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot write the file (" + e.what() + ")");
    }
    file.commit();
}

}  // namespace dacrt
