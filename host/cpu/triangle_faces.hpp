#pragma once
// The triangle bounds a triangle filter reads.
#include <cstddef>

#include "core/scene.hpp"

namespace dacrt::simd {

// The records, or where a frame has them the same coordinates in columns
// (FrameGeometry::boundsColumns): a filter then uses every byte it brings into the caches,
// where from the 32-byte records it uses 4, and the partitions of a large scene wait on memory.
struct TriangleFaces {
    const Bounds* bounds = nullptr;
    const float* columns = nullptr;  // null: the records are read
    std::size_t count = 0;           // the columns' length: the frame's triangles
};

}  // namespace dacrt::simd
