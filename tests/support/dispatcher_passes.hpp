#pragma once
// A set's secondary passes through the dispatcher, as every frame's passes go: each traced on
// brute force first, the reference the other backends and shapes are held to.
#include <gtest/gtest.h>

#include "library/backend_dispatcher.hpp"
#include "support/frames.hpp"

namespace dacrt::test {

// For each pass of the set: its brute-force trace, then check(primary, pass, reference).
template <typename Check>
void forEachPassAgainstBruteForce(const SecondaryPassSet& set, BackendDispatcher& dispatcher, Check&& check) {
    const FrameGeometry primary =
        frameGeometry(set.frame.scene.triangles, set.frame.bounds, set.frame.rays, sceneBounds(set.frame.scene.triangles));
    for (const auto& [name, pass] : set.passes) {
        SCOPED_TRACE(set.name + ", " + name);
        BackendRequest request;
        request.trace.threads = 2;
        request.trace.backend = Backend::Brute;
        const BackendDispatcher::PassTrace reference = dispatcher.traceSecondary(primary, set.primary.hits, pass, request);
        ASSERT_GT(reference.rays, 500u);
        check(primary, pass, reference);
    }
}

}  // namespace dacrt::test
