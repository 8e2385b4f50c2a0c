#include "gpu/resident_triangles.hpp"

namespace dacrt::gpu {

bool ResidentTriangles::holds(const FrameGeometry& g) const {
    return triangles_ && g.trianglesVersion != 0 && g.trianglesVersion == version_ && g.triangles->size() == count_;
}

void ResidentTriangles::prepare(const Context& context, const FrameGeometry& g, std::uint64_t chunkBytes) {
    if (holds(g) && chunkBytes == chunkBytes_) return;
    const std::uint64_t n = g.triangles->size();
    if (!triangles_ || count_ != n || chunkBytes != chunkBytes_) {
        triangles_.reset();
        bounds_.reset();
        triangles_ = std::make_unique<Buffer>(context, n * sizeof(Triangle), "triangles", BufferUse::Storage, chunkBytes);
        bounds_ = std::make_unique<Buffer>(context, n * sizeof(Bounds), "triangle bounds", BufferUse::Storage, chunkBytes);
        chunkBytes_ = chunkBytes;
    }
    triangles_->upload(g.triangles->data(), n * sizeof(Triangle));
    bounds_->upload(g.triangleBounds->data(), n * sizeof(Bounds));
    version_ = g.trianglesVersion;
    count_ = n;
}

}  // namespace dacrt::gpu
