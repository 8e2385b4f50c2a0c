#pragma once
// A perspective camera's primary rays several pixels per instruction (Google Highway, the best
// instruction set the machine has, chosen at run time): the bits of makeRay(origin, forward +
// sx right + sy up), pixel by pixel, which PixelRays::ray makes one at a time. The same
// double-precision arithmetic in the same order (divisions and square roots are correctly
// rounded in every lane, as in scalar code), so the same rays.
#include <glm/glm.hpp>

#include "core/scene.hpp"

namespace dacrt {

// PixelRays' perspective camera.
struct PerspectivePixels {
    glm::dvec2 offset{0.5, 0.5};  // the point of the pixel, in pixel units from its top-left corner
    double width = 1.0, height = 1.0;  // the image's, in pixels
    double halfHeight = 0.0, aspect = 1.0;
    glm::dvec3 right{0.0}, forward{0.0}, up{0.0};
    glm::vec3 origin{0.0f};  // finite (the caller checks)
};

// The rays of pixels x0 .. x0 + count - 1 of row y into out[0 .. count - 1]. Returns how many
// it made: all of them, or those before the first pixel whose direction is zero, not finite,
// or so long or short that its squares overflow or underflow (makeRay makes the rest: it names
// the fault, or scales the direction).
int perspectiveRowRays(const PerspectivePixels& pixels, int y, int x0, int count, Ray* out);

// A 4x4 tile's rays, lane l the pixel (x0 + l % 4, y0 + l / 4), their origin and dir alone (a
// tracer that reads no other field: the Embree peer's packets); the same count as
// perspectiveRowRays, of 16.
int perspectiveTileDirections(const PerspectivePixels& pixels, int x0, int y0, Ray* out);

}  // namespace dacrt
