#pragma once
// The frame's triangles and their bounds kept on the device from one frame to the next while
// they do not change (the uploads skip): an orbit, or the static part of an animation, pays
// for their upload once. "Do not change" is the caller's word, FrameGeometry::trianglesVersion,
// as a renderer tells its ray tracer which buffers it updated; 0 means unknown, uploaded.
#include <cstdint>
#include <memory>

#include "cpu/frame_geometry.hpp"
#include "gpu/buffer.hpp"

namespace dacrt::gpu {

class ResidentTriangles {
public:
    // Whether the buffers already hold g's triangles and bounds.
    bool holds(const FrameGeometry& g) const;
    // Makes them hold g's (allocating and uploading unless holds(g)), in chunks of chunkBytes
    // where the frame addresses its arrays (0: one binding each).
    void prepare(const Context& context, const FrameGeometry& g, std::uint64_t chunkBytes = 0);
    Buffer& triangles() { return *triangles_; }
    Buffer& bounds() { return *bounds_; }

private:
    std::unique_ptr<Buffer> triangles_, bounds_;
    std::uint64_t version_ = 0;
    std::uint64_t count_ = 0;
    std::uint64_t chunkBytes_ = 0;
};

}  // namespace dacrt::gpu
