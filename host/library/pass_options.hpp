#pragma once
// The secondary passes a command asks for (--light, --ao): the lights and options of the core
// scene made into the public API's FramePass list (Tracer::traceFrame), checked before any
// work.
#include <cstdint>
#include <string>
#include <vector>

#include <dacrt/frame.hpp>

#include "core/lights.hpp"
#include "core/scene.hpp"

namespace dacrt {

// What the command line asks of the secondary passes.
struct PassOptions {
    std::vector<std::string> lights;  // --light values; empty: the scene's lights, else a key light
    std::uint32_t occlusionSamples = 0;  // --ao
    double occlusionDistance = 0.0;      // --ao-distance; 0: a tenth of the scene box's diagonal
};

// Throws InputError on a bad --light, --ao or --ao-distance, before anything is loaded.
void checkPassOptions(const PassOptions& options);

// The occlusion rays' length: --ao-distance, or a tenth of the scene box's diagonal.
float occlusionDistance(const PassOptions& options, const Box& sceneBox);

// The passes as the public API describes them: one shadow pass per light, then the occlusion
// pass (with --ao), in the order their results are shaded. seed picks the occlusion sample sequence (an
// antialiasing sample's own).
std::vector<FramePass> framePasses(const std::vector<Light>& lights, const PassOptions& options, const Box& sceneBox,
                                   std::uint32_t seed);

}  // namespace dacrt
