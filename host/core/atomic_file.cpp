#include "core/atomic_file.hpp"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <set>
#include <system_error>

#include <unistd.h>

#include "core/errors.hpp"

namespace dacrt {
namespace {

// The temporaries of this process's live AtomicFiles. The lock also orders a commit's rename
// against the signal thread's removal: a file is either renamed into place or removed.
// Never destroyed: a file may be written from a destructor that runs after static destruction
// began (a pipeline store kept by some static owner).
std::mutex& unfinishedMutex() {
    static auto* m = new std::mutex;
    return *m;
}

std::multiset<std::string>& unfinished() {
    static auto* files = new std::multiset<std::string>;
    return *files;
}

void forget(const std::string& temporary) {
    auto& files = unfinished();
    if (auto it = files.find(temporary); it != files.end()) files.erase(it);
}

}  // namespace

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
    const std::lock_guard<std::mutex> lock(unfinishedMutex());
    unfinished().insert(temporary_);
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    const std::lock_guard<std::mutex> lock(unfinishedMutex());
    forget(temporary_);
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
}

void AtomicFile::commit() {
    const std::lock_guard<std::mutex> lock(unfinishedMutex());
    std::error_code ec;
    std::filesystem::rename(temporary_, path_, ec);
    if (ec) throw InputError(path_ + ": cannot write the file (" + ec.message() + ")");
    forget(temporary_);
    committed_ = true;
}

std::vector<std::string> removeUnfinishedTemporariesForExit() {
    unfinishedMutex().lock();  // never unlocked: the caller ends the process
    std::vector<std::string> removed;
    for (const std::string& path : unfinished())
        if (::unlink(path.c_str()) == 0) removed.push_back(path);
    return removed;
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
