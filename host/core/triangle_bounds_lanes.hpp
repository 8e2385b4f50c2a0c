#pragma once
// A frame's triangle bounds, one vertex per 4-lane vector (Google Highway, chosen at run
// time): each lane the scalar code's compare and select (glm::min and glm::max), in the same
// order, so the same bits, the sign of a zero included.
#include <cstddef>

#include "core/scene.hpp"

namespace dacrt {

// bounds[i] = triangleBounds(triangles[i]) for i in [0, count), and box extended by every
// vertex in order (Box::extend of v0, v1, v2 of each triangle): what the scalar loop makes.
void triangleBoundsLanes(const Triangle* triangles, std::size_t count, Bounds* bounds, Box& box);

}  // namespace dacrt
