#pragma once
// The memory a frame will take, buffer by buffer, computed from the counts before anything
// is allocated: printed by --plan, checked against the machine, recorded in --stats.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace dacrt {

// One line of a frame's work plan: a count of what the frame will do or skip, and why.
struct WorkLine {
    std::string name;
    std::uint64_t count = 0;
    std::string why;
};

// The frame's plan: its memory buffer by buffer, and (`work`) what it will trace and skip,
// with counts, in the order the stages decide it.
struct MemoryPlan {
    std::vector<std::pair<std::string, std::uint64_t>> buffers;
    std::vector<WorkLine> work;
    void add(const std::string& name, std::uint64_t bytes) { buffers.emplace_back(name, bytes); }
    void addWork(const std::string& name, std::uint64_t count, const std::string& why = {}) {
        work.push_back({name, count, why});
    }
    void append(const MemoryPlan& more) {
        buffers.insert(buffers.end(), more.buffers.begin(), more.buffers.end());
        work.insert(work.end(), more.work.begin(), more.work.end());
    }
    std::string describeWork() const;
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

// onPlan seeing the plan with `lines` added to its work (before the stage's own lines, or
// after): how a stage that decided something before the tracer plans puts it in the plan.
// Empty when onPlan is; `lines` must outlive the hook.
inline PlanHook withWorkLines(const PlanHook& onPlan, const std::vector<WorkLine>& lines, bool before) {
    if (!onPlan) return {};
    return [&onPlan, &lines, before](const MemoryPlan& plan) {
        MemoryPlan whole = plan;
        whole.work.insert(before ? whole.work.begin() : whole.work.end(), lines.begin(), lines.end());
        return onPlan(whole);
    };
}

}  // namespace dacrt
