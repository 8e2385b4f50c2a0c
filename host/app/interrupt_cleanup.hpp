#pragma once
// A run stopped by SIGTERM or SIGINT (how Slurm and Kubernetes pre-empt, and Ctrl-C) removes the
// temporary file it was writing and exits with 128 + the signal's number, as a shell reports a
// process the signal ended. Files already renamed into place stay: they are complete.

namespace dacrt {

// Blocks SIGTERM and SIGINT in this thread and every thread it starts from now on, and starts
// one thread that waits for them, removes every unfinished AtomicFile temporary and exits. Call
// it before any other thread starts (the worker pools, the Vulkan driver's threads), so that no thread is left
// where the signal's default action would end the process without the cleanup.
void stopCleanlyOnSignals();

}  // namespace dacrt
