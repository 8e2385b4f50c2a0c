#pragma once
// Vulkan for the tests: a shared context on the default device (lavapipe in CI) with the
// validation layers on, or a skip with a message where no Vulkan device exists.
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "gpu/context.hpp"

namespace dacrt::test {

// The context is made once per test binary; its validation error count is checked by every
// GPU test (and must stay 0).
inline gpu::Context* gpuContext(std::string* why) {
    static std::unique_ptr<gpu::Context> context;
    static std::string reason;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            // No pipeline file: tests leave the user's cache alone (test_pipeline_store.cpp tests it).
            context = std::make_unique<gpu::Context>(gpu::ContextOptions{"", true, false});
        } catch (const std::exception& e) {
            reason = e.what();
        }
    }
    if (why) *why = reason;
    return context.get();
}

#define DACRT_REQUIRE_GPU(var)                                                          \
    std::string var##Why;                                                               \
    ::dacrt::gpu::Context* var = ::dacrt::test::gpuContext(&var##Why);                   \
    if (!var) GTEST_SKIP() << "no Vulkan device with validation layers: " << var##Why

// Validation messages of error severity must never appear.
inline ::testing::AssertionResult noValidationErrors(const gpu::Context& context) {
    if (context.validationErrors() == 0) return ::testing::AssertionSuccess();
    std::string text;
    for (const std::string& m : context.validationMessages()) text += "\n" + m;
    return ::testing::AssertionFailure() << context.validationErrors() << " validation errors:" << text;
}

}  // namespace dacrt::test
