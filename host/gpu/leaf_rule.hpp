#pragma once
// The C++ side of shaders/leaf_rule.glsl: the kernel's leaf balance, for the host's tests.
#include "core/shader_layout.hpp"

namespace dacrt::gpu::shared {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
namespace {  // GLSL has no `inline`: internal linkage keeps one copy per translation unit legal
#include "leaf_rule.glsl"
}
#pragma GCC diagnostic pop
}  // namespace dacrt::gpu::shared
