#pragma once
// A fixture that runs a body on every SIMD target this machine runs (simd::forceTarget
// chooses Highway's target for every dispatched function, the cpu kernels' and the core's
// rows and bounds alike), then leaves the best one chosen again.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cpu/simd_kernels.hpp"

namespace dacrt::test {

class OnEveryTarget : public ::testing::Test {
protected:
    template <typename Body>
    void forEachTarget(Body body) {
        const std::vector<std::string> targets = simd::availableTargets();
        ASSERT_FALSE(targets.empty());
        for (const std::string& t : targets) {
            SCOPED_TRACE("target " + t);
            simd::forceTarget(t);
            ASSERT_EQ(simd::activeTarget(), t);
            body();
        }
    }
    void TearDown() override { simd::forceTarget(""); }
};

}  // namespace dacrt::test
