#pragma once
// Every output a command will write, checked before any work: its folder exists and can be
// written, it is not a folder, its format suits what goes in it, and it is neither an input
// nor another output. Nothing here creates a folder.
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
};

// Throws InputError naming the option and the path.
void checkOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<std::string>& inputs);

}  // namespace dacrt
