#pragma once
// The kernel's stage clocks (shaders/stage_clocks.glsl, GpuTuning::stageClocks): the stages'
// names and their ticks as the counters hold them.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/shader_layout.hpp"

namespace dacrt::gpu {

// DACRT_STAGE_* k's name: "ray partitions", ..., "launches".
const char* stageName(std::size_t stage);

// Each stage's 64-bit sum of ticks, in DACRT_STAGE_* order.
std::vector<std::uint64_t> stageTicksOf(const GpuCounters& counters);

}  // namespace dacrt::gpu
