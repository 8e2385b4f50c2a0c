// The processor named in every bench record: the /proc/cpuinfo "model name" with its family
// and model, so that two VMs both called "AMD EPYC" are told apart.
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/cpu_model.hpp"

namespace dacrt {
namespace {

std::string firstValue(const std::string& key) {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line) && !line.empty())
        if (line.rfind(key, 0) == 0 && line.find_first_not_of(" \t", key.size()) == line.find(':'))
            return line.substr(line.find_first_not_of(" \t", line.find(':') + 1));
    return {};
}

TEST(CpuModel, NamesTheProcessorWithItsFamilyAndModel) {
    const std::string name = firstValue("model name"), family = firstValue("cpu family"), model = firstValue("model");
    if (name.empty() || family.empty() || model.empty()) GTEST_SKIP() << "/proc/cpuinfo has no model name, family and model here";
    EXPECT_EQ(cpuModelName(), name + " (family " + family + ", model " + model + ")");
}

}  // namespace
}  // namespace dacrt
