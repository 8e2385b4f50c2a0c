#include "hit_arrays.hpp"

#include <limits>
#include <span>

#include <dacrt/errors.hpp>

namespace dacrt::python {

HitArrays::HitArrays(const Shape& rays)
    : tHit_(arrayOf<float>(rays)), primitiveIds_(arrayOf<std::uint32_t>(rays)), uvs_(arrayOf<float>(rays, 2)),
      normals_(arrayOf<float>(rays, 3)), tData_(tHit_.mutable_data()), idData_(primitiveIds_.mutable_data()),
      uvData_(uvs_.mutable_data()), normalData_(normals_.mutable_data()), count_(elementCount(rays)) {}

void HitArrays::fill(const std::vector<RayHit>& hits, const TraceScene& scene) {
    if (hits.size() != count_)
        throw InternalError("the trace returned " + std::to_string(hits.size()) + " hits for " + std::to_string(count_) +
                            " rays");
    for (std::size_t i = 0; i < count_; ++i) {
        const RayHit& h = hits[i];
        // A miss's t is the ray's tmax in the library; here, as in Open3D and the AOV's Z, +inf.
        tData_[i] = h.hit() ? h.t : std::numeric_limits<float>::infinity();
        idData_[i] = h.primitive;
        uvData_[2 * i] = h.hit() ? h.u : 0.0f;
        uvData_[2 * i + 1] = h.hit() ? h.v : 0.0f;
    }
    scene.geometricNormals(std::span<const std::uint32_t>(idData_, count_), std::span<float>(normalData_, 3 * count_));
}

py::dict HitArrays::toDict() const {
    py::dict d;
    d["t_hit"] = tHit_;
    d["primitive_ids"] = primitiveIds_;
    d["primitive_uvs"] = uvs_;
    d["primitive_normals"] = normals_;
    return d;
}

}  // namespace dacrt::python
