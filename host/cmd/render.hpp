#pragma once
// The render command: scene in, one traced frame per camera, images and stats out.
#include <string>

#include "cmd/backend_dispatcher.hpp"
#include "cmd/frame_passes.hpp"
#include "core/camera.hpp"

namespace dacrt {

struct RenderOptions {
    std::string scenePath;
    std::string sceneChoice;   // --scene: an index or name among the file's scenes; empty: its default
    std::string cameraChoice;  // --camera: an index or name among the cameras the scene places; empty: the first
    std::string outputPath;   // shaded image; empty: none
    std::string aovPath;      // EXR AOVs; empty: none
    std::string statsPath;    // JSON; empty: none
    std::string depthPngPath;   // viewable depth; empty: none
    std::string normalPngPath;  // viewable normals; empty: none
    int samplesPerPixel = 1;  // shaded image only: k x k strata per pixel (a square); AOVs keep the centre
    int width = 640;
    int height = 480;
    bool planOnly = false;    // print the work and memory plans and stop before tracing
    CullMode cull = CullMode::Material;
    DeviceChoice devices;     // gpu
    BackendRequest request;
    CameraOptions camera;
    PassOptions passes;       // lights (shadow passes) and ambient occlusion
};

// With K cameras, each output name gets "_camN" before its extension.
std::string pathForCamera(const std::string& path, int camera, int cameraCount);

// Returns the exit code (cmd/exit_codes.hpp); throws InputError on bad input.
int runRender(const RenderOptions& options);

}  // namespace dacrt
