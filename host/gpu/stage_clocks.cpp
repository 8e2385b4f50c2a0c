#include "gpu/stage_clocks.hpp"

#include <array>

namespace dacrt::gpu {

const char* stageName(std::size_t stage) {
    static constexpr std::array<const char*, DACRT_STAGE_COUNT> kNames = {
        "ray partitions", "triangle partitions", "leaf tests", "stack and slices", "waiting", "launches"};
    static_assert(DACRT_STAGE_RAY_PARTITIONS == 0 && DACRT_STAGE_TRIANGLE_PARTITIONS == 1 && DACRT_STAGE_LEAF_TESTS == 2 &&
                  DACRT_STAGE_STACK_AND_SLICES == 3 && DACRT_STAGE_WAITING == 4 && DACRT_STAGE_LAUNCHES == 5);
    return stage < kNames.size() ? kNames[stage] : "unknown stage";
}

std::vector<std::uint64_t> stageTicksOf(const GpuCounters& counters) {
    std::vector<std::uint64_t> ticks(DACRT_STAGE_COUNT);
    for (std::size_t k = 0; k < ticks.size(); ++k)
        ticks[k] = std::uint64_t(counters.stageTicks[2 * k]) | std::uint64_t(counters.stageTicks[2 * k + 1]) << 32;
    return ticks;
}

}  // namespace dacrt::gpu
