#pragma once
// The public Tracer of the stress tests: one per test binary, opened with the gpu backend and
// its Vulkan device (validation layers on) where one exists, so that validation errors
// accumulate and pipelines are compiled once; each test switches it to its own options.
#include <memory>
#include <string>

#include <dacrt/tracer.hpp>

namespace dacrt::test {

// whyNoGpu: where the tracer has no device, why it could not open one.
inline Tracer& testTracer(std::string* whyNoGpu = nullptr) {
    static std::unique_ptr<Tracer> tracer;
    static std::string reason;
    if (!tracer) {
        TracerOptions options;
        options.trace.backend = Backend::Gpu;
        options.validate = true;
        try {
            tracer = std::make_unique<Tracer>(options);
        } catch (const std::exception& e) {
            reason = e.what();
            tracer = std::make_unique<Tracer>(TracerOptions{});
        }
    }
    if (whyNoGpu) *whyNoGpu = reason;
    return *tracer;
}

}  // namespace dacrt::test
