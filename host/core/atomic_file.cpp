#include "core/atomic_file.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>

#include <fcntl.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "core/output_target.hpp"

namespace dacrt {
namespace {

// The temporaries of this process's live batches. The lock also orders a commit's renames
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

// ".STEM.partial-PID-N.EXT" beside the target: hidden, and with the target's extension.
std::string temporaryNameFor(const std::string& target) {
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path p(target);
    std::string name = ".";  // appended piece by piece: GCC 12 warns falsely on a chain of operator+
    name += p.stem().string();
    name += ".partial-";
    name += std::to_string(getpid());
    name += "-";
    name += std::to_string(counter++);
    name += p.extension().string();
    return (p.parent_path() / name).string();
}

[[noreturn]] void failWrite(const std::string& path, const char* step, int error) {
    throw InputError(path + ": cannot write the file (" + step + ": " + std::strerror(error) + ")");
}

// Every byte, through short writes and interruptions; then, for a regular file, synced, so
// that an error the file system reports late (a full disk, EIO) is seen here; then closed.
void writeToEnd(int fd, std::string_view bytes, const std::string& path, bool sync) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int error = n < 0 ? errno : EIO;
            ::close(fd);
            failWrite(path, "write", error);
        }
        done += std::size_t(n);
    }
    if (sync && ::fsync(fd) != 0) {
        const int error = errno;
        ::close(fd);
        failWrite(path, "sync", error);
    }
    if (::close(fd) != 0 && errno != EINTR) failWrite(path, "close", errno);
}

}  // namespace

OutputBatch::~OutputBatch() {
    if (committed_) return;
    const std::lock_guard<std::mutex> lock(unfinishedMutex());
    for (const Staged& s : staged_) {
        if (s.temporary.empty()) continue;
        forget(s.temporary);
        ::unlink(s.temporary.c_str());
    }
}

void OutputBatch::add(const std::string& path, std::string_view bytes) {
    const OutputTarget target = resolveOutputTarget(path);
    if (target.writeThrough) {
        staged_.push_back({path, target.path, {}, std::string(bytes)});
        return;
    }
    Staged s{path, target.path, temporaryNameFor(target.path), {}};
    {
        const std::lock_guard<std::mutex> lock(unfinishedMutex());
        unfinished().insert(s.temporary);
    }
    staged_.push_back(s);  // before the write: the destructor removes what it leaves
    const int fd = ::open(s.temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) failWrite(path, "create", errno);
    writeToEnd(fd, bytes, path, true);
}

void OutputBatch::commit() {
    for (Staged& s : staged_) {
        if (!s.temporary.empty()) continue;
        const int fd = ::open(s.target.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd < 0) failWrite(s.path, "open", errno);
        writeToEnd(fd, s.bytes, s.path, false);
        s.bytes.clear();
    }
    const std::lock_guard<std::mutex> lock(unfinishedMutex());
    std::vector<const Staged*> renamed;
    for (const Staged& s : staged_) {
        if (s.temporary.empty()) continue;
        if (::rename(s.temporary.c_str(), s.target.c_str()) != 0) {
            const int error = errno;
            for (const Staged* r : renamed) ::unlink(r->target.c_str());
            failWrite(s.path, "rename", error);  // the destructor removes the temporaries left
        }
        renamed.push_back(&s);
    }
    for (const Staged& s : staged_) forget(s.temporary);
    committed_ = true;
}

void writeFileAtomically(const std::string& path, std::string_view contents) {
    OutputBatch batch;
    batch.add(path, contents);
    batch.commit();
}

std::vector<std::string> removeUnfinishedTemporariesForExit() {
    unfinishedMutex().lock();  // never unlocked: the caller ends the process
    std::vector<std::string> removed;
    for (const std::string& path : unfinished())
        if (::unlink(path.c_str()) == 0) removed.push_back(path);
    return removed;
}

}  // namespace dacrt
