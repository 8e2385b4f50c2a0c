#pragma once
// Every output a command will write, checked before any work: its folder exists and can be
// written, it is not a folder, its format suits what goes in it, and it is neither an input
// nor another output. Nothing here creates a folder.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace dacrt {

enum class OutputFormat {
    Image,  // any format OpenImageIO writes, chosen by the extension (8-bit RGB)
    Exr,    // multi-channel AOVs: OpenEXR only
    Text,   // JSON, CSV
};

struct PlannedOutput {
    std::string option;  // as the user named it, for the message ("-o", "--aov")
    std::string path;    // empty: not requested
    OutputFormat format;
    std::string context;  // where it was expanded, for a message ("frame 12, camera 1"); empty: none
};

// The name whose extension chooses the format an output is encoded in: its own; without one,
// that of the file a link names (/dev/stdout redirected to a file), or for a device or FIFO
// (/dev/stdout on a pipe, a named pipe) PNG for an image and OpenEXR for AOVs.
std::string encodingNameFor(const std::string& path, OutputFormat format);

// Throws InputError naming the option and the path: a folder that does not exist or cannot be
// written, a file that cannot be written, a folder, socket or block device, a dangling link
// (core/output_target.hpp), a format that does not suit, or a file that is the input's or
// another output's (through links and ".." too).
void checkOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<std::string>& inputs);
// The same over `count` outputs made on demand (outputAt may be called more than once for an
// index): a frame range names up to millions of files, which are never all held at once.
void checkOutputs(std::size_t count, const std::function<PlannedOutput(std::size_t)>& outputAt,
                  const std::vector<std::string>& inputs);

}  // namespace dacrt
