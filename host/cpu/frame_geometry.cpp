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

bool raysShareStart(const std::vector<Ray>& rays, ThreadPool* pool) {
    if (rays.empty()) return true;
    const Ray& first = rays.front();
    return firstFailureInChunks(rays.size(), kFrameScanChunk, pool, [&](std::size_t i) {
               return std::memcmp(&rays[i].origin, &first.origin, sizeof(first.origin)) == 0 &&
                      std::memcmp(&rays[i].tmin, &first.tmin, sizeof(first.tmin)) == 0;
           }) == rays.size();
}

bool raysShareSegment(const std::vector<Ray>& rays) {
    return !rays.empty() &&
           std::all_of(rays.begin(), rays.end(), [&](const Ray& r) { return sameSegment(r, rays.front()); });
}

void fillTracedTriangleIds(const FrameGeometry& g, std::vector<std::uint32_t>& ids, ThreadPool* pool) {
    ids.resize(g.tracedTriangleCount());
    forEachChunk(ids.size(), kFrameScanChunk, pool, [&](std::size_t, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) ids[i] = g.tracedTriangle(i);
    });
}

FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox, std::uint32_t imageWidth,
                            ThreadPool* pool, bool uniformRays) {
    FrameGeometry g;
    g.triangles = &triangles;
    g.triangleBounds = &bounds;
    g.rays = &rays;
    g.sceneBox = sceneBox;
    g.rayOrigin = rays.empty() ? glm::vec3(0.0f) : rays.front().origin;
    g.uniformByConstruction = uniformRays && !rays.empty();
    g.raysShareStart = g.uniformByConstruction || (!rays.empty() && raysShareStart(rays, pool));
    if (g.raysShareStart) {
        g.farthestOrigin = glm::abs(g.rayOrigin);
        g.nearSide = g.rayOrigin;
    } else {
        // Each chunk's farthest origin and directions, then their maxima and unions: the same
        // on every thread count.
        struct Reach {
            glm::vec3 farthest{0.0f};
            bool towardLow[3] = {false, false, false}, towardHigh[3] = {false, false, false};
        };
        std::vector<Reach> reach((rays.size() + kFrameScanChunk - 1) / kFrameScanChunk);
        forEachChunk(rays.size(), kFrameScanChunk, pool, [&](std::size_t c, std::size_t begin, std::size_t end) {
            Reach r;  // written to reach[c] once: neighbouring chunks' entries share cache lines
            for (std::size_t i = begin; i < end; ++i)
                for (int a = 0; a < 3; ++a) {
                    r.farthest[a] = std::max(r.farthest[a], std::abs(rays[i].origin[a]));
                    r.towardLow[a] |= rays[i].dir[a] < 0.0f;
                    r.towardHigh[a] |= rays[i].dir[a] > 0.0f;
                }
            reach[c] = r;
        });
        bool towardLow[3] = {false, false, false}, towardHigh[3] = {false, false, false};
        for (const Reach& r : reach)
            for (int a = 0; a < 3; ++a) {
                g.farthestOrigin[a] = std::max(g.farthestOrigin[a], r.farthest[a]);
                towardLow[a] |= r.towardLow[a];
                towardHigh[a] |= r.towardHigh[a];
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
