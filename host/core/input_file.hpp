#pragma once
// Input files are read whole and only when they are regular files of a size that fits: a FIFO
// or a device (/dev/zero, /dev/stdin) would block or never end, and a size is checked before
// anything is allocated for it.
#include <cstdint>
#include <string>
#include <vector>

namespace dacrt {

// The size of the regular file at path (symbolic links followed). Throws InputError naming
// path when it does not exist, is not a regular file (saying what it is), or is larger than
// maxBytes (0: no limit).
std::uint64_t regularInputSize(const std::string& path, std::uint64_t maxBytes);

// Its bytes, after regularInputSize's checks; a file that changes size while read is an error.
std::vector<unsigned char> readRegularInput(const std::string& path, std::uint64_t maxBytes);

}  // namespace dacrt
