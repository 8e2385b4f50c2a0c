#pragma once
// The processor's name, for the machine record of every measured figure: the VMs this project
// runs on change CPU between sessions, and a time means nothing without the CPU it ran on.
#include <string>

namespace dacrt {

// The "model name" of /proc/cpuinfo with its family and model (for example "AMD EPYC (family
// 26, model 2)"), or "" where there is none.
std::string cpuModelName();

}  // namespace dacrt
