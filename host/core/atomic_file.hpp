#pragma once
// A file written under a temporary name beside its destination and renamed into place when
// complete, so that a failed or interrupted write never leaves a partial file. Every
// AtomicFile's temporary is known to the process while it exists, so that a run stopped by a
// signal can remove them (removeUnfinishedTemporariesForExit).
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.hpp"

namespace dacrt {

class AtomicFile {
public:
    explicit AtomicFile(std::string path);
    ~AtomicFile();  // removes the temporary file unless committed
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    // Where to write: the destination's folder, a hidden name, the destination's extension (so
    // that image libraries choose the same format).
    const std::string& temporaryPath() const { return temporary_; }
    // Renames the temporary file to the destination; throws InputError if that fails.
    void commit();

private:
    std::string path_;
    std::string temporary_;
    bool committed_ = false;
};

}  // namespace dacrt

namespace dacrt {

// Removes the temporary of every AtomicFile this process has not committed or dropped, and keeps
// any other from being made, committed or dropped until the process ends: for the one thread
// that ends the process on a signal (cmd/interrupt_cleanup). Returns the paths removed.
std::vector<std::string> removeUnfinishedTemporariesForExit();

// Writes `contents` to path through an AtomicFile; throws InputError naming the path.
void writeFileAtomically(const std::string& path, const std::string& contents);

// Calls write(temporaryPath) and renames the result into place; a failure names `path`.
template <typename Write>
void writeThrough(const std::string& path, Write write) {
    AtomicFile file(path);
    try {
        write(file.temporaryPath());
    } catch (const std::exception& e) {
        throw InputError(path + ": cannot write the file (" + e.what() + ")");
    }
    file.commit();
}

}  // namespace dacrt
