#pragma once
// One traced frame as the image stages see it: the rays in pixel order and their hits.
#include <vector>

#include "core/shader_layout.hpp"

namespace dacrt {

struct HitImage {
    int width = 0;
    int height = 0;
    const std::vector<Ray>* rays = nullptr;
    const std::vector<Hit>* hits = nullptr;
};

}  // namespace dacrt
