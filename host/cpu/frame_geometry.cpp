#include "cpu/frame_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/errors.hpp"

namespace dacrt {

float filterMargin(const Box& sceneBox, const glm::vec3& farthestOrigin) {
    float m = 0.0f;
    for (int a = 0; a < 3; ++a)
        m = std::max({m, std::abs(sceneBox.lo[a]), std::abs(sceneBox.hi[a]), std::abs(farthestOrigin[a])});
    return std::max(m * 0x1p-18f, 0x1p-100f);
}

bool raysShareStart(const std::vector<Ray>& rays) {
    return std::all_of(rays.begin(), rays.end(), [&](const Ray& r) {
        return std::memcmp(&r.origin, &rays.front().origin, sizeof(r.origin)) == 0 &&
               std::memcmp(&r.tmin, &rays.front().tmin, sizeof(r.tmin)) == 0;
    });
}

bool raysShareSegment(const std::vector<Ray>& rays) {
    return !rays.empty() &&
           std::all_of(rays.begin(), rays.end(), [&](const Ray& r) { return sameSegment(r, rays.front()); });
}

FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox, std::uint32_t imageWidth) {
    FrameGeometry g;
    g.triangles = &triangles;
    g.triangleBounds = &bounds;
    g.rays = &rays;
    g.sceneBox = sceneBox;
    g.rayOrigin = rays.empty() ? glm::vec3(0.0f) : rays.front().origin;
    g.raysShareStart = !rays.empty() && raysShareStart(rays);
    if (g.raysShareStart) {
        g.farthestOrigin = glm::abs(g.rayOrigin);
        g.nearSide = g.rayOrigin;
    } else {
        bool towardLow[3] = {false, false, false}, towardHigh[3] = {false, false, false};
        for (const Ray& r : rays)
            for (int a = 0; a < 3; ++a) {
                g.farthestOrigin[a] = std::max(g.farthestOrigin[a], std::abs(r.origin[a]));
                towardLow[a] |= r.dir[a] < 0.0f;
                towardHigh[a] |= r.dir[a] > 0.0f;
            }
        for (int a = 0; a < 3; ++a) {
            g.nearSide[a] = towardLow[a] ? std::numeric_limits<float>::max() : -std::numeric_limits<float>::max();
            if (towardLow[a] && towardHigh[a]) g.order = ChildOrder::PerRay;
        }
        if (g.order == ChildOrder::PerRay) g.nearSide = glm::vec3(0.0f);
    }
    g.margin = filterMargin(sceneBox, g.farthestOrigin);
    g.imageWidth = imageWidth && rays.size() % imageWidth == 0 ? imageWidth : 0;
    return g;
}

}  // namespace dacrt
