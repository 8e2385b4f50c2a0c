#pragma once
// How much memory this machine has: the limit every plan is checked against before long work.
#include <cstdint>

namespace dacrt {

// Physical memory in bytes, or 0 where the system does not say.
std::uint64_t physicalMemoryBytes();

}  // namespace dacrt
