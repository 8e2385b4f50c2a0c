#include "core/input_file.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"

namespace dacrt {

namespace {

const char* kindOf(mode_t mode) {
    return S_ISDIR(mode) ? "a folder" : S_ISFIFO(mode) ? "a FIFO" : S_ISCHR(mode) ? "a character device"
                                      : S_ISBLK(mode) ? "a block device" : S_ISSOCK(mode) ? "a socket" : "not a regular file";
}

}  // namespace

std::uint64_t regularInputSize(const std::string& path, std::uint64_t maxBytes) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0)
        throw InputError(path + (errno == ENOENT ? std::string(": no such file") : ": cannot read the file (" + std::string(std::strerror(errno)) + ")"));
    if (!S_ISREG(st.st_mode))
        throw InputError(path + ": is " + kindOf(st.st_mode) + "; dacrt reads inputs from regular files only");
    const std::uint64_t size = std::uint64_t(st.st_size);
    if (maxBytes && size > maxBytes)
        throw InputError(path + ": the file has " + std::to_string(size) + " bytes, more than the " +
                         std::to_string(maxBytes) + " bytes it may take (over by " + std::to_string(size - maxBytes) + ")");
    return size;
}

std::vector<unsigned char> readRegularInput(const std::string& path, std::uint64_t maxBytes) {
    const std::uint64_t size = regularInputSize(path, maxBytes);
    // O_NONBLOCK: should the file be swapped for a FIFO since the check, open does not wait.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw InputError(path + ": cannot read the file (" + std::strerror(errno) + ")");
    struct stat st{};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || std::uint64_t(st.st_size) != size) {
        ::close(fd);
        throw InputError(path + ": the file changed while it was opened");
    }
    std::vector<unsigned char> bytes = mappedArray<unsigned char>(size);
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::read(fd, bytes.data() + done, size - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int error = n < 0 ? errno : 0;
            ::close(fd);
            throw InputError(path + ": cannot read the file (" +
                             (error ? std::string(std::strerror(error)) : std::string("it became shorter while read")) + ")");
        }
        done += std::size_t(n);
    }
    ::close(fd);
    return bytes;
}

}  // namespace dacrt
