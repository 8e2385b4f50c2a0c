#pragma once
// Lets C++ compile the GLSL sources in shaders/ that define layouts and predicates, so the
// CPU backends run exactly the arithmetic the compute shaders run.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

namespace dacrt::shared {
using namespace glm;
using uint = std::uint32_t;
// glm::abs branches on the sign (unpredictable in the filters); these hide it for floats.
inline float abs(float x) { return std::fabs(x); }
inline float min(float a, float b) { return b < a ? b : a; }
inline float max(float a, float b) { return a < b ? b : a; }
#define precise
#define IN(T) const T&
#include "layout.h"
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
namespace {  // GLSL has no `inline`: internal linkage keeps one copy per translation unit legal
#include "predicates.glsl"
}
#pragma GCC diagnostic pop
#undef IN
#undef precise
}  // namespace dacrt::shared

namespace dacrt {
using shared::Bounds;
using shared::DacrtPush;
using shared::GpuCounters;
using shared::WorkgroupTestPush;
using shared::WorkItem;
using shared::Hit;
using shared::Ray;
using shared::StackEntry;
using shared::TraversalState;
using shared::Region;
using shared::Triangle;
using shared::kMissPrim;
using shared::kNoHitT;
}  // namespace dacrt
