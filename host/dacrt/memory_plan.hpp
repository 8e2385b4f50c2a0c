#pragma once
// The memory a frame will take, buffer by buffer, computed from the counts before anything
// is allocated: printed by --plan, checked against the machine, recorded in --stats.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace dacrt {

struct MemoryPlan {
    std::vector<std::pair<std::string, std::uint64_t>> buffers;
    void add(const std::string& name, std::uint64_t bytes) { buffers.emplace_back(name, bytes); }
    std::uint64_t total() const {
        std::uint64_t t = 0;
        for (const auto& b : buffers) t += b.second;
        return t;
    }
    std::string describe() const;
};

// Called with the complete memory plan after the counting passes and before the id arrays
// are allocated or anything is traced. Returning false stops the frame there: the result
// then holds the plan and no hits. It may also throw (a plan that does not fit).
using PlanHook = std::function<bool(const MemoryPlan&)>;

}  // namespace dacrt
