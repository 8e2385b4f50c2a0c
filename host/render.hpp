#pragma once
// The render command: scene in, one traced frame per camera, images and stats out.
#include <cstdint>
#include <string>

#include "camera.hpp"
#include "trace_types.hpp"

namespace dacrt {

struct RenderOptions {
    std::string scenePath;
    std::string outputPath;   // shaded image; empty: none
    std::string aovPath;      // EXR AOVs; empty: none
    std::string statsPath;    // JSON; empty: none
    int width = 640;
    int height = 480;
    bool planOnly = false;    // print the memory plan and stop before tracing
    std::string device;       // gpu: index or part of the name
    bool validate = false;    // gpu: Vulkan validation layers; errors make the run fail
    std::uint32_t workgroupSize = 0;  // gpu: 0 = the device's default
    std::uint32_t rayGroups = 0;      // gpu: 0 = the device's default
    bool embreeFast = false;          // embree: without RTC_SCENE_FLAG_ROBUST
    TraceOptions trace;
    CameraOptions camera;
};

// With K cameras, each output name gets "_camN" before its extension.
std::string pathForCamera(const std::string& path, int camera, int cameraCount);

int runRender(const RenderOptions& options);

}  // namespace dacrt
