// The bench's plan of what it holds at once (bench/bench_memory.hpp): every configuration's
// kept state where it all fits, one at a time where only each alone fits, a refusal naming the
// configuration where even that does not; and the order of a camera's frames under each.
#include <gtest/gtest.h>

#include "bench/bench_memory.hpp"
#include "core/errors.hpp"

namespace dacrt {
namespace {

BenchMemoryPlan planOf(std::uint64_t held, std::uint64_t budget, std::vector<ConfigMemory> configs) {
    BenchMemoryPlan plan;
    plan.held = held;
    plan.budget = budget;
    plan.budgetOrigin = "a test's budget";
    plan.configs = std::move(configs);
    return plan;
}

TEST(BenchMemory, KeepsEveryStateWhereAllFitAndOneAtATimeWhereEachFitsAlone) {
    const std::vector<std::string> labels = {"cpu", "embree dynamic", "embree static"};
    // Held 100; kept 0 + 300 + 200 beside the largest frame (50): 650.
    BenchMemoryPlan plan = planOf(100, 650, {{0, 50}, {300, 10}, {200, 10}});
    EXPECT_EQ(plan.allKept(), 650u);
    EXPECT_EQ(plan.largestAlone(), 410u);
    chooseHolding(plan, labels, "scene");
    EXPECT_FALSE(plan.oneAtATime);

    plan.budget = 649;
    chooseHolding(plan, labels, "scene");
    EXPECT_TRUE(plan.oneAtATime);
    plan.budget = 410;
    chooseHolding(plan, labels, "scene");
    EXPECT_TRUE(plan.oneAtATime);

    plan.budget = 409;  // embree dynamic alone (100 + 300 + 10) no longer fits
    try {
        chooseHolding(plan, labels, "scene");
        FAIL() << "a configuration that does not fit alone was not refused";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("embree dynamic on scene needs about 310 bytes"), std::string::npos) << message;
        EXPECT_NE(message.find("over by 1 bytes"), std::string::npos) << message;
        EXPECT_NE(message.find("a test's budget"), std::string::npos) << message;
    }

    plan.budget = 0;  // the machine does not say: nothing to plan against
    chooseHolding(plan, labels, "scene");
    EXPECT_FALSE(plan.oneAtATime);
}

TEST(BenchMemory, FramesInterleaveUnlessOneConfigurationIsHeldAtATime) {
    using Order = std::vector<std::pair<int, std::size_t>>;
    EXPECT_EQ(frameOrder(2, 3, false), (Order{{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}}));
    EXPECT_EQ(frameOrder(2, 3, true), (Order{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {0, 2}, {1, 2}}));
    EXPECT_TRUE(frameOrder(0, 3, true).empty());
}

}  // namespace
}  // namespace dacrt
