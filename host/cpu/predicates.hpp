#pragma once
// Lets C++ compile shaders/predicates.glsl (ray/box, triangle/box, the watertight test, the
// tie rule), so that the CPU backends run exactly the arithmetic the compute shaders run.
#include <cmath>

#include "core/shader_layout.hpp"

namespace dacrt::shared {
// glm::abs branches on the sign (unpredictable in the filters); these hide it for floats.
inline float abs(float x) { return std::fabs(x); }
inline float min(float a, float b) { return b < a ? b : a; }
inline float max(float a, float b) { return a < b ? b : a; }
#define precise
#define IN(T) const T&
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
namespace {  // GLSL has no `inline`: internal linkage keeps one copy per translation unit legal
#include "predicates.glsl"
}
#pragma GCC diagnostic pop
#undef IN
#undef precise
}  // namespace dacrt::shared
