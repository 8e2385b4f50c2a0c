#pragma once
#include <string>

#include "core/scene.hpp"

namespace dacrt {

// Loads the default scene of a glTF 2.0 file (.gltf or .glb) and flattens every triangle
// primitive into world space. Bad files throw InputError naming the file and the problem.
Scene loadGltf(const std::string& path);

}  // namespace dacrt
