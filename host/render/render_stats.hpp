#pragma once
// The --stats JSON of one rendered frame (one camera at one instant).
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <dacrt/frame.hpp>
#include <dacrt/results.hpp>

#include "render/render.hpp"
#include "core/scene.hpp"

namespace dacrt {

struct RenderedFrame {
    const Scene& scene;
    const Camera& camera;
    int cameraIndex = 0;
    FrameInstant instant;                                   // the frame number (of a range) and its time
    std::size_t rayCount = 0;
    const TraceOutput& result;  // the primary pass
    // load, evaluate_animation, prepare, shader_compile, trace, secondary_passes,
    // antialiasing_samples, write, total
    std::vector<std::pair<std::string, double>> timingsMs;
    const std::vector<PassOutput>* passes = nullptr;        // the secondary passes
    std::vector<Light> lights;                              // the lights shaded with (none: headlight)
    float exposure = 1.0f;
};

nlohmann::ordered_json renderStatsJson(const RenderOptions& options, const RenderedFrame& frame);

}  // namespace dacrt
