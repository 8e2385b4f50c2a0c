#pragma once
// The render command: scene in, one traced frame per camera and instant (one, or each frame of
// a range, or of this process's shard of it), images and stats out.
#include <optional>
#include <string>

#include <dacrt/tracer.hpp>

#include "cpu/options.hpp"  // the option enums' names
#include "library/pass_options.hpp"
#include "render/frame_range.hpp"
#include "render/frame_shards.hpp"
#include "core/camera.hpp"

namespace dacrt {

struct RenderOptions {
    std::string scenePath;
    std::string sceneChoice;   // --scene: an index or name among the file's scenes; empty: its default
    std::string cameraChoice;  // --camera: an index or name among the cameras the scene places; empty: the first
    std::string animationChoice;  // --animation: an index or name; empty: every animation together
    std::optional<double> time;   // --time: the one instant (seconds); none: 0 s, or the frames' times
    std::optional<FrameRange> frames;  // --frames: a range of frame numbers
    double fps = kDefaultFps;     // --fps: frame n is at n / fps seconds
    bool fpsGiven = false;
    ShardRequest shards;          // --shard, --shard-count, --shard-mode
    bool skipExisting = false;    // --skip-existing: a frame whose every output exists is not rendered
    // Every output name may hold a frame number pattern (frame_pattern.hpp).
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
    TracerOptions tracer;     // the backend and its options, the device (gpu, rayquery)
    CameraOptions camera;
    PassOptions passes;       // lights (shadow passes) and ambient occlusion
};

// With K cameras, each output name gets "_camN" before its extension.
std::string pathForCamera(const std::string& path, int camera, int cameraCount);

// Returns the exit code (cmd/exit_codes.hpp); throws InputError on bad input.
int runRender(const RenderOptions& options);

}  // namespace dacrt
