#include "core/atomic_file.hpp"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include <unistd.h>

#include "core/errors.hpp"

namespace dacrt {

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path p(path_);
    std::string name = ".";  // appended piece by piece: GCC 12 warns falsely on a chain of operator+
    name += p.stem().string();
    name += ".partial-";
    name += std::to_string(getpid());
    name += "-";
    name += std::to_string(counter++);
    name += p.extension().string();
    temporary_ = (p.parent_path() / name).string();
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
}

void AtomicFile::commit() {
    std::error_code ec;
    std::filesystem::rename(temporary_, path_, ec);
    if (ec) throw InputError(path_ + ": cannot write the file (" + ec.message() + ")");
    committed_ = true;
}

}  // namespace dacrt

#include <fstream>

namespace dacrt {

void writeFileAtomically(const std::string& path, const std::string& contents) {
    AtomicFile file(path);
    {
        std::ofstream out(file.temporaryPath(), std::ios::binary);
        out << contents;
        if (!out.flush()) throw InputError(path + ": cannot write the file");
    }
    file.commit();
}

}  // namespace dacrt
