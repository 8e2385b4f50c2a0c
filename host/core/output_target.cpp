#include "core/output_target.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <sys/stat.h>

#include "core/errors.hpp"

namespace dacrt {

namespace fs = std::filesystem;

OutputTarget resolveOutputTarget(const std::string& path) {
    struct stat link{};
    if (::lstat(path.c_str(), &link) != 0) {
        if (errno == ENOENT) return {path, false, false};  // a new file
        throw InputError(path + ": cannot use as an output (" + std::strerror(errno) + ")");
    }
    std::string target = path;
    if (S_ISLNK(link.st_mode)) {
        std::error_code ec;
        struct stat named{};
        if (::stat(path.c_str(), &named) != 0)
            throw InputError(path + ": a symbolic link to " + fs::read_symlink(path, ec).string() + ", which " +
                             (errno == ENOENT ? std::string("does not exist (a dangling link is not written through)")
                                              : std::string("cannot be reached (") + std::strerror(errno) + ")"));
        link = named;
        // A device or FIFO is opened through the link (/dev/stdout names a pipe by a path that
        // does not resolve); a regular file is replaced where it lies, the link kept.
        if (S_ISREG(named.st_mode)) {
            target = fs::canonical(path, ec).string();
            if (ec) throw InputError(path + ": a symbolic link that cannot be followed (" + ec.message() + ")");
        }
    }
    if (S_ISREG(link.st_mode)) return {target, false, true};
    if (S_ISCHR(link.st_mode) || S_ISFIFO(link.st_mode)) return {target, true, true};
    const char* what = S_ISDIR(link.st_mode)    ? "a folder"
                       : S_ISSOCK(link.st_mode) ? "a socket"
                       : S_ISBLK(link.st_mode)  ? "a block device"
                                                : "not a regular file";
    throw InputError(path + ": is " + std::string(what) + ", not a file an output can be written to");
}

}  // namespace dacrt
