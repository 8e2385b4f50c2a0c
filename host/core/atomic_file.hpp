#pragma once
// Outputs written all or none. Each regular file's bytes go to a temporary beside it, written
// to the end, synced and closed, every step checked (a full disk, a file size limit, an I/O
// error or a short write is an error naming the file), and the temporaries are renamed into
// place together once all are complete: a failed or interrupted write never leaves a partial
// file, nor a frame's image without the stats that failed after it. Outputs that are
// character devices or FIFOs are written through (core/output_target.hpp). Every temporary is
// known to the process while it exists, so that a run stopped by a signal can remove them
// (removeUnfinishedTemporariesForExit).
#include <string>
#include <string_view>
#include <vector>

namespace dacrt {

class OutputBatch {
public:
    OutputBatch() = default;
    ~OutputBatch();  // removes every temporary not renamed into place
    OutputBatch(const OutputBatch&) = delete;
    OutputBatch& operator=(const OutputBatch&) = delete;

    // Writes `bytes` for `path` now: to its temporary for a regular file (a symbolic link's
    // target), or keeps them for commit() for a device or FIFO. Throws InputError naming path.
    void add(const std::string& path, std::string_view bytes);

    // Writes the devices and FIFOs, then renames every temporary into place. On a failure it
    // removes this batch's outputs already renamed and throws InputError: the batch leaves all
    // of its files or none (bytes a device or FIFO took cannot be taken back).
    void commit();

private:
    struct Staged {
        std::string path;       // as the caller named it
        std::string target;     // the file written (a link's target)
        std::string temporary;  // empty: written through at commit
        std::string bytes;      // written through only
    };
    std::vector<Staged> staged_;
    bool committed_ = false;
};

// One file through an OutputBatch of its own.
void writeFileAtomically(const std::string& path, std::string_view contents);

// Removes the temporary of every OutputBatch this process has not committed or dropped, and
// keeps any other from being made, committed or dropped until the process ends: for the one
// thread that ends the process on a signal (app/interrupt_cleanup). Returns the paths removed.
std::vector<std::string> removeUnfinishedTemporariesForExit();

}  // namespace dacrt
