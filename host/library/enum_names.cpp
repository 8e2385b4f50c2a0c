// The public names of the backends and face rules (include/dacrt/names.hpp): the command
// line's tables (cpu/options.hpp, core/scene.hpp).
#include <dacrt/names.hpp>

#include "core/scene.hpp"
#include "cpu/options.hpp"

namespace dacrt {

std::string backendName(Backend backend) { return toString(backend); }
std::optional<Backend> backendNamed(std::string_view name) { return parseEnum<Backend>(name); }
std::vector<std::string> backendNames() { return enumNameList<Backend>(); }

std::string cullModeName(CullMode mode) { return toString(mode); }
std::optional<CullMode> cullModeNamed(std::string_view name) { return parseEnum<CullMode>(name); }
std::vector<std::string> cullModeNames() { return enumNameList<CullMode>(); }

}  // namespace dacrt
