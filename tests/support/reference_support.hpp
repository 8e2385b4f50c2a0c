#pragma once
// Comparison of float64 reference frames for the tests.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oracle/reference_tracer.hpp"

namespace dacrt::test {

// Same primitive and the same t (both infinite counts as the same) for every ray.
inline ::testing::AssertionResult sameReference(const std::vector<ReferenceHit>& a, const std::vector<ReferenceHit>& b) {
    std::size_t differing = 0;
    std::string first;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].prim != b[i].prim || !(a[i].t == b[i].t || (std::isinf(a[i].t) && std::isinf(b[i].t))))
            if (++differing == 1)
                first = "ray " + std::to_string(i) + ": prim " + std::to_string(a[i].prim) + " vs " + std::to_string(b[i].prim);
    if (a.size() != b.size()) return ::testing::AssertionFailure() << "sizes differ";
    if (differing) return ::testing::AssertionFailure() << differing << " rays differ, first " << first;
    return ::testing::AssertionSuccess();
}

}  // namespace dacrt::test
