#pragma once
// A FramePlan as `dacrt render --plan` prints it: aligned lines, sizes in readable units.
#include <string>

#include <dacrt/results.hpp>

namespace dacrt {

std::string describeMemory(const FramePlan& plan);  // a line per buffer, then the total
std::string describeWork(const FramePlan& plan);    // a line per stage: its count and why

}  // namespace dacrt
