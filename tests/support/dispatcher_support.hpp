#pragma once
// The backend dispatcher for the command-layer tests: one per test binary, with the Vulkan
// device (validation layers on) where one exists, so that validation errors accumulate and
// pipelines are compiled once.
#include <memory>
#include <string>

#include "library/backend_dispatcher.hpp"

namespace dacrt::test {

inline BackendDispatcher& testDispatcher(std::string* whyNoGpu = nullptr) {
    static std::unique_ptr<BackendDispatcher> dispatcher;
    static std::string reason;
    if (!dispatcher) {
        try {
            dispatcher = std::make_unique<BackendDispatcher>(DeviceChoice{"", true}, std::vector<Backend>{Backend::Gpu});
        } catch (const std::exception& e) {
            reason = e.what();
            dispatcher = std::make_unique<BackendDispatcher>(DeviceChoice{}, std::vector<Backend>{});
        }
    }
    if (whyNoGpu) *whyNoGpu = reason;
    return *dispatcher;
}

}  // namespace dacrt::test
