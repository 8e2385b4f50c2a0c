#pragma once
// The C++ side of shaders/triangle_rules.glsl: the degenerate-triangle rule, written once.
#include "core/shader_layout.hpp"

namespace dacrt::shared {
#define precise
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
namespace {  // GLSL has no `inline`: internal linkage keeps one copy per translation unit legal
#include "triangle_rules.glsl"
}
#pragma GCC diagnostic pop
#undef precise
}  // namespace dacrt::shared
