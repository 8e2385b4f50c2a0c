#pragma once
// The info command: what a glTF file holds, and the chosen scene's triangles and bounds.
#include <string>

namespace dacrt {

struct InfoOptions {
    std::string scenePath;
    std::string sceneChoice;  // an index or name; empty: the file's default scene
};

// Prints the inventory to stdout; returns the exit code. Throws InputError on a bad file.
int runInfo(const InfoOptions& options);

}  // namespace dacrt
