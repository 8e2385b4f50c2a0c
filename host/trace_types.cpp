#include "trace_types.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace dacrt {

std::string toString(Backend b) {
    switch (b) {
        case Backend::Brute: return "brute";
        case Backend::CpuSeq: return "cpu-seq";
        case Backend::Cpu: return "cpu";
        case Backend::Gpu: return "gpu";
        case Backend::Embree: return "embree";
    }
    return "?";
}

std::string toString(SplitMethod s) {
    switch (s) {
        case SplitMethod::SpatialMedian: return "spatial-median";
        case SplitMethod::CentroidMean: return "centroid-mean";
        case SplitMethod::SampledMean: return "sampled-mean";
    }
    return "?";
}

std::string toString(DivisionAxis a) {
    switch (a) {
        case DivisionAxis::Best: return "best";
        case DivisionAxis::X: return "x";
        case DivisionAxis::Y: return "y";
        case DivisionAxis::Z: return "z";
    }
    return "?";
}

std::string toString(Intersector i) {
    return i == Intersector::Watertight ? "watertight" : "moller-trumbore";
}

std::string toString(TriangleFilter f) {
    switch (f) {
        case TriangleFilter::Bounds: return "bounds";
        case TriangleFilter::Sat: return "sat";
        case TriangleFilter::Mora: return "mora";
    }
    return "?";
}

std::string toString(Precision p) { return p == Precision::F32 ? "f32" : "f64"; }

float filterMargin(const Box& sceneBox, const glm::vec3& rayOrigin) {
    float m = 0.0f;
    for (int a = 0; a < 3; ++a)
        m = std::max({m, std::abs(sceneBox.lo[a]), std::abs(sceneBox.hi[a]), std::abs(rayOrigin[a])});
    return std::max(m * 0x1p-18f, 0x1p-100f);
}

FrameGeometry frameGeometry(const std::vector<Triangle>& triangles, const std::vector<Bounds>& bounds,
                            const std::vector<Ray>& rays, const Box& sceneBox) {
    FrameGeometry g;
    g.triangles = &triangles;
    g.triangleBounds = &bounds;
    g.rays = &rays;
    g.sceneBox = sceneBox;
    g.rayOrigin = rays.front().origin;
    g.margin = filterMargin(sceneBox, g.rayOrigin);
    return g;
}

std::string MemoryPlan::describe() const {
    std::ostringstream s;
    for (const auto& [name, bytes] : buffers)
        s << "  " << name << std::string(name.size() < 28 ? 28 - name.size() : 1, ' ') << bytes << " bytes ("
          << std::fixed << double(bytes) / (1024.0 * 1024.0) << " MiB)\n";
    s << "  total" << std::string(23, ' ') << total() << " bytes (" << std::fixed
      << double(total()) / (1024.0 * 1024.0) << " MiB)\n";
    return s.str();
}

}  // namespace dacrt
