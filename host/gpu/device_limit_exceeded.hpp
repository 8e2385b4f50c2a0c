#pragma once
// A frame beyond a limit of the device that fewer triangles per frame would keep it within:
// the device's memory for the frame's buffers together, or on llvmpipe the loop budget of a
// work item's largest single step. Thrown when the frame is planned, before any buffer is
// allocated or dispatch recorded, so that the caller may trace the frame's triangles in batches
// instead (library/triangle_batches.hpp). Its message names the limit and the excess.
#include <cstdint>
#include <string>

#include "core/errors.hpp"

namespace dacrt::gpu {

class DeviceLimitExceeded : public InputError {
public:
    DeviceLimitExceeded(const std::string& message, std::string limitName, std::uint64_t needed, std::uint64_t limit)
        : InputError(message), limitName(std::move(limitName)), needed(needed), limit(limit) {}
    std::string limitName;  // "the device's memory (...)", "the loop budget of a step"
    std::uint64_t needed = 0, limit = 0;  // in the limit's own units
};

}  // namespace dacrt::gpu
