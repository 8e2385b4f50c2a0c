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
    // Whether the buffers already hold g's triangles and bounds in a form a frame whose
    // addressed arrays are in chunks of chunkBytes (0: bound whole) reaches (Buffer::suitsChunks):
    // then prepare uploads nothing.
    bool holds(const FrameGeometry& g, std::uint64_t chunkBytes) const;
    // Makes them hold g's so (allocating where the count or the chunks do not suit, and
    // uploading), unless holds(g, chunkBytes).
    void prepare(const Context& context, const FrameGeometry& g, std::uint64_t chunkBytes);
    Buffer& triangles() { return *triangles_; }
    Buffer& bounds() { return *bounds_; }
    // How many times prepare uploaded them: what the plan's upload lines report.
    std::uint64_t uploads() const { return uploads_; }

private:
    bool suits(std::uint64_t count, std::uint64_t chunkBytes) const;

    std::unique_ptr<Buffer> triangles_, bounds_;
    std::uint64_t version_ = 0;
    std::uint64_t count_ = 0;
    std::uint64_t uploads_ = 0;
};

}  // namespace dacrt::gpu
