#pragma once
// The --stats JSON of one rendered frame.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cmd/render.hpp"
#include "core/scene.hpp"

namespace dacrt {

struct RenderedFrame {
    const Scene& scene;
    const Camera& camera;
    int cameraIndex = 0;
    std::size_t rayCount = 0;
    const TraceResult& result;
    std::vector<std::pair<std::string, double>> timingsMs;  // load, prepare, trace, write, total
    const std::vector<TracedPass>* passes = nullptr;        // the secondary passes
    std::vector<Light> lights;                              // the lights shaded with (none: headlight)
    float exposure = 1.0f;
};

nlohmann::ordered_json renderStatsJson(const RenderOptions& options, const RenderedFrame& frame);

}  // namespace dacrt
