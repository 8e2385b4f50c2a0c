#pragma once
// dacrt: divide-and-conquer ray tracing, with no acceleration structure, on the CPU (SIMD,
// every core) and on a Vulkan device; Embree and the device's ray queries as peers.
//
//     #include <dacrt/dacrt.hpp>
//
//     std::vector<float> positions = {-1, -1, -1, 1, -1, -1, 0, 1, -1};   // x, y, z per vertex
//     std::vector<std::uint32_t> indices = {0, 1, 2};                      // three per triangle
//     dacrt::TraceScene scene = dacrt::TraceScene::fromArrays(positions, indices);
//     std::vector<float> origin = {0, 0, 0}, direction = {0, 0, -1};
//     dacrt::RayBatch rays = dacrt::RayBatch::fromArrays(origin, direction);
//     dacrt::Tracer tracer({.trace = {.backend = dacrt::Backend::Cpu}});
//     dacrt::TraceOutput out = tracer.trace(scene, rays);
//     if (out.hits[0].hit()) std::printf("triangle %u at t = %g\n", out.hits[0].primitive, out.hits[0].t);
//
// The parts, one header each:
//   scene.hpp           TraceScene: triangles from a glTF file (scene_options.hpp: which scene,
//                       when, which camera, which face rule) or from arrays with a single-sided
//                       flag per triangle, whose vertices may move between traces (setPositions);
//                       the hit triangles' geometric normals
//   rays.hpp            RayBatch: a camera's rays (as `dacrt render` makes them) or any rays
//                       with their segments (tmin < t <= tmax), origins and directions apart
//                       or six floats per ray (fromRays), t a distance or in units of the
//                       direction as given (DirectionLength); writeRays gives them back
//   tracer.hpp          Tracer: a backend with its options (options.hpp, backend_tuning.hpp);
//                       trace() gives each ray's closest hit, occluded() whether anything lies
//                       on it, plan() the memory and work a trace needs, without tracing
//                       traceFrame() a camera's frame with its shadow and occlusion passes
//   frame.hpp           FramePass (a shadow or occlusion pass), FrameOutput, passPlanBound
//   results.hpp         RayHit (primitive id, t, u, v), TraceTimings, TraceCounters, FramePlan
//   device_report.hpp   DeviceReport: the gpu's dispatches and work items
//   plan_text.hpp       a FramePlan as `dacrt render --plan` prints it
//   errors.hpp          InputError (bad input, with a message naming it), InternalError
//   scene_info.hpp      describeSceneFile: what a glTF file holds (scenes, cameras, lights,
//                       animations, meshes, materials, extensions), as `dacrt info` prints it
//   devices.hpp         listDevices: the processor with its SIMD kernels and every Vulkan
//                       device with its limits, as `dacrt devices` prints them
//   names.hpp           the command line's names of the backends and face rules, both ways
//
// brute, cpu-seq, cpu and gpu return the same primitive id and t, bit for bit, for every ray
// (docs/correctness.md); embree and rayquery are peers with their own answers. A Tracer opens
// its threads and device once: keep it for many traces (setOptions switches its options or
// backend between them); the peers keep their acceleration structure in it from trace to trace
// (tracer.hpp says what each trace costs).
// A TraceScene, RayBatch or Tracer may be used from one thread at a time.
#include <dacrt/backend_tuning.hpp>
#include <dacrt/devices.hpp>
#include <dacrt/device_report.hpp>
#include <dacrt/errors.hpp>
#include <dacrt/frame.hpp>
#include <dacrt/names.hpp>
#include <dacrt/options.hpp>
#include <dacrt/plan_text.hpp>
#include <dacrt/rays.hpp>
#include <dacrt/results.hpp>
#include <dacrt/scene.hpp>
#include <dacrt/scene_info.hpp>
#include <dacrt/scene_options.hpp>
#include <dacrt/tracer.hpp>
