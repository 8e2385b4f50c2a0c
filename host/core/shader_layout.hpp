#pragma once
// The C++ side of shaders/layout.h, the one header of data layouts that GLSL and C++ share
// (with its static_asserts); dacrt/predicates.hpp does the same for the predicates.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

namespace dacrt::shared {
using namespace glm;
using uint = std::uint32_t;
#include "layout.h"
}  // namespace dacrt::shared

namespace dacrt {
using shared::Bounds;
using shared::DacrtPush;
using shared::SecondaryPush;
using shared::ShadowLight;
using shared::GpuCounters;
using shared::WorkgroupTestPush;
using shared::WorkItem;
using shared::PacketBounds;
using shared::Hit;
using shared::Ray;
using shared::StackEntry;
using shared::TraversalState;
using shared::Region;
using shared::Triangle;
using shared::kMissPrim;
using shared::kNotTracedPrim;
using shared::kUnnamedHitPrim;
using shared::kNoHitT;
}  // namespace dacrt
