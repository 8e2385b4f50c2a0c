#include "gpu/resident_triangles.hpp"

namespace dacrt::gpu {

bool ResidentTriangles::suits(std::uint64_t count, std::uint64_t chunkBytes) const {
    return triangles_ && bounds_ && count_ == count && triangles_->suitsChunks(chunkBytes) &&
           bounds_->suitsChunks(chunkBytes);
}

bool ResidentTriangles::holds(const FrameGeometry& g, std::uint64_t chunkBytes) const {
    return g.trianglesVersion != 0 && g.trianglesVersion == version_ && suits(g.triangles->size(), chunkBytes);
}

void ResidentTriangles::prepare(const Context& context, const FrameGeometry& g, std::uint64_t chunkBytes) {
    if (holds(g, chunkBytes)) return;
    const std::uint64_t n = g.triangles->size();
    version_ = 0;  // until the upload below completes
    if (!suits(n, chunkBytes)) {
        triangles_.reset();
        bounds_.reset();
        triangles_ = std::make_unique<Buffer>(context, n * sizeof(Triangle), "triangles", BufferUse::Storage, chunkBytes);
        bounds_ = std::make_unique<Buffer>(context, n * sizeof(Bounds), "triangle bounds", BufferUse::Storage, chunkBytes);
        count_ = n;
    }
    triangles_->upload(g.triangles->data(), n * sizeof(Triangle));
    bounds_->upload(g.triangleBounds->data(), n * sizeof(Bounds));
    version_ = g.trianglesVersion;
    ++uploads_;
}

}  // namespace dacrt::gpu
