#include "dacrt/frame_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace dacrt {

float filterMargin(const Box& sceneBox, const glm::vec3& rayOrigin) {
    float m = 0.0f;
    for (int a = 0; a < 3; ++a)
        m = std::max({m, std::abs(sceneBox.lo[a]), std::abs(sceneBox.hi[a]), std::abs(rayOrigin[a])});
    return std::max(m * 0x1p-18f, 0x1p-100f);
}

bool raysShareStart(const std::vector<Ray>& rays) {
    return std::all_of(rays.begin(), rays.end(), [&](const Ray& r) {
        return std::memcmp(&r.origin, &rays.front().origin, sizeof(r.origin)) == 0 &&
               std::memcmp(&r.tmin, &rays.front().tmin, sizeof(r.tmin)) == 0;
    });
}

FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox, std::uint32_t imageWidth) {
    FrameGeometry g;
    g.triangles = &triangles;
    g.triangleBounds = &bounds;
    g.rays = &rays;
    g.sceneBox = sceneBox;
    g.rayOrigin = rays.front().origin;
    g.margin = filterMargin(sceneBox, g.rayOrigin);
    g.raysShareStart = raysShareStart(rays);
    g.imageWidth = imageWidth && rays.size() % imageWidth == 0 ? imageWidth : 0;
    return g;
}

}  // namespace dacrt
