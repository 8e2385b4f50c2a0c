#pragma once
// Where an output's bytes go. A symbolic link is followed to the file it names, as cp and
// convert do (the link stays a link); a character device or a FIFO (/dev/null, /dev/stdout,
// a named pipe) is written through, never replaced; anything else that is not a regular file
// is refused. Commands check every output this way before any work, and the write checks again.
#include <string>

namespace dacrt {

struct OutputTarget {
    std::string path;           // the file written: the link's target for a symbolic link
    bool writeThrough = false;  // a character device or FIFO: opened and written in place
    bool exists = false;        // something is there now (a regular file is replaced)
};

// Throws InputError naming `path`: a folder, a socket, a block device, a dangling or looping
// symbolic link.
OutputTarget resolveOutputTarget(const std::string& path);

}  // namespace dacrt
