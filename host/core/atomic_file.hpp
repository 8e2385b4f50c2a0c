#pragma once
// A file written under a temporary name beside its destination and renamed into place when
// complete, so that a failed or interrupted write never leaves a partial file.
#include <stdexcept>
#include <string>

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
