#pragma once
// The names the command line gives the public enums (--backend, --cull), for callers that take
// them as text, such as the Python module: the command line's own tables, read, not copied.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dacrt/options.hpp>
#include <dacrt/scene_options.hpp>

namespace dacrt {

std::string backendName(Backend backend);              // "brute", "cpu-seq", "cpu", "gpu", "embree", "rayquery"
std::optional<Backend> backendNamed(std::string_view name);  // nullopt: no backend has that name
std::vector<std::string> backendNames();               // every backend, in the command line's order

std::string cullModeName(CullMode mode);               // "material", "none", "backfaces"
std::optional<CullMode> cullModeNamed(std::string_view name);
std::vector<std::string> cullModeNames();

}  // namespace dacrt
