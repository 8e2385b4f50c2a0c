#include "core/cpu_model.hpp"

#include <fstream>

namespace dacrt {
namespace {

// The value of a "key : value" line of /proc/cpuinfo.
std::string valueOf(const std::string& line) {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) return {};
    const std::size_t first = line.find_first_not_of(" \t", colon + 1);
    return first == std::string::npos ? std::string() : line.substr(first);
}

}  // namespace

std::string cpuModelName() {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line, name, family, model;
    // The first processor's block only: it ends at the first empty line.
    while (std::getline(cpuinfo, line) && !line.empty()) {
        if (line.rfind("model name", 0) == 0) name = valueOf(line);
        else if (line.rfind("cpu family", 0) == 0) family = valueOf(line);
        else if (line.rfind("model", 0) == 0 && line.find_first_not_of(" \t", 5) == line.find(':')) model = valueOf(line);
    }
    // VMs often hide the product name ("AMD EPYC"); the family and model still tell the
    // generation apart (AMD family 25 is Zen 3 and Zen 4, 26 Zen 5).
    if (family.empty() || model.empty()) return name;
    std::string generation = "(family ";
    generation.append(family).append(", model ").append(model).append(")");
    return name.empty() ? generation : name + " " + generation;
}

}  // namespace dacrt
