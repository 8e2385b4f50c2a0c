#pragma once
// Temporaries a killed run left behind: OutputBatch writes ".STEM.partial-PID-N.EXT" beside
// STEM.EXT, and a run ended by SIGKILL (or a crash) cannot remove its own. A re-run removes
// those of its own output names whose process is gone from this machine.
#include <string>
#include <vector>

namespace dacrt {

// Removes every temporary of `outputs` (final names) whose writer's process no longer exists,
// and returns the paths removed. A live process's temporary (another run writing the same
// name now) is left alone. Only this run's names are looked at: runs of other shards, which
// may live on other machines of a shared file system, write other names.
std::vector<std::string> removeStaleTemporaries(const std::vector<std::string>& outputs);

}  // namespace dacrt
