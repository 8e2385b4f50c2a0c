#pragma once
// A ray-query scene: one bottom-level acceleration structure over a frame's triangles (read
// in place as 16-byte vertex slots, the layout of shaders/layout.h's Triangle) and a top level
// holding it once, built on the device into buffers made once.
#include <cstdint>
#include <memory>

#include "gpu/buffer.hpp"

namespace dacrt::gpu {

// How the structure is built, as a Vulkan user chooses for each case: fast build (rebuilt
// every frame), updatable (refitted every frame), fast trace (built once).
enum class AccelerationBuild { FastBuild, Updatable, FastTrace };

// Whether the instance reports facing (FrontOnly: culling allowed, facing as glTF's
// counter-clockwise front) or disables it (Both).
enum class Faces { Both, FrontOnly };

// Throws InputError naming the extensions the device lacks for ray queries.
void requireRayQuery(const DeviceInfo& info);

class TriangleAccelerationStructure {
public:
    // Sizes and allocates everything for `triangleCount` triangles whose vertices lie in
    // `vertices` (which must outlive the structure). Throws InputError naming what the device
    // lacks when it has no ray query.
    TriangleAccelerationStructure(const Context& context, const Buffer& vertices, std::uint64_t triangleCount,
                                  AccelerationBuild mode, Faces faces);
    ~TriangleAccelerationStructure();
    TriangleAccelerationStructure(const TriangleAccelerationStructure&) = delete;
    TriangleAccelerationStructure& operator=(const TriangleAccelerationStructure&) = delete;

    // Records the build of both levels (update: the bottom level refitted in place, valid
    // after one build, for an Updatable structure only).
    void record(VkCommandBuffer commands, bool update) const;

    VkAccelerationStructureKHR topLevel() const;
    std::uint64_t bytes() const;  // the buffers' total, for the memory plan

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace dacrt::gpu
