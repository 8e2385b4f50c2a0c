#pragma once
// A run stopped by SIGTERM, SIGINT or SIGHUP (how Slurm and Kubernetes pre-empt, Ctrl-C, a
// closed terminal) removes the temporary files it was writing and exits with 128 + the
// signal's number, as a shell reports a process the signal ended. Files already renamed into
// place stay: they are complete.

namespace dacrt {

// Ignores SIGPIPE and SIGXFSZ (a write to a FIFO without a reader, or past the file size
// limit, then fails with EPIPE or EFBIG and is reported as an error), blocks
// SIGTERM, SIGINT and SIGHUP in this thread and every thread it starts from now on, and starts
// one thread that waits for them, removes every unfinished OutputBatch temporary and exits. Call
// it before any other thread starts (the worker pools, the Vulkan driver's threads), so that no thread is left
// where the signal's default action would end the process without the cleanup.
void stopCleanlyOnSignals();

}  // namespace dacrt
