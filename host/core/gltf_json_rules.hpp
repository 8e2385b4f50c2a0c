#pragma once
// The specification's type, integer and reference rules, checked on the glTF JSON itself before
// tinygltf converts it. tinygltf reads an integer member through a cast to int (2^32 becomes
// 0), reads a member of the wrong type (0.5 where an index belongs, a string where an array
// does) as if it were absent, and resolves no reference: each of these would load a file the
// specification refuses, as some other file. Internal to the glTF loader.
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace dacrt::gltf {

// Throws InputError naming the file (`name`), the member's JSON path and its value when a
// top-level collection is not an array of objects, extensionsUsed or extensionsRequired not an
// array of strings, an object the rules walk through not an object, an index, count or enum
// member not a non-negative integer that its C++ type holds, or an index out of range of the
// array it names (every index of the core specification and of the extensions dacrt reads).
void checkJsonRules(const nlohmann::json& doc, const std::string& name);

}  // namespace dacrt::gltf
