#pragma once
// Embree computes a hit's t with its own arithmetic: its AVX2 kernels round it a few ulps off
// the exact value where its AVX-512 ones did not. The DACRT backends and brute force give it
// bit for bit; tests of the peer allow it this much.
#include <cmath>
#include <limits>

namespace dacrt::test {

inline float embreeTTolerance(float exact) { return 4.0f * std::numeric_limits<float>::epsilon() * std::fabs(exact); }

}  // namespace dacrt::test
