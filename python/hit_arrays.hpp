#pragma once
// A trace's hits as the arrays cast_rays and render return, shaped as the rays: t_hit (+inf on
// a miss), primitive_ids (INVALID_ID on a miss), primitive_uvs (the barycentric weights of the
// second and third vertex; 0 on a miss) and primitive_normals (unit geometric normals; 0 on a
// miss), as `dacrt render --aov` writes Z, primId, u, v and N.
#include <cstdint>
#include <vector>

#include <pybind11/numpy.h>

#include <dacrt/results.hpp>
#include <dacrt/scene.hpp>

#include "numpy_arrays.hpp"

namespace dacrt::python {

class HitArrays {
public:
    // Allocated with the GIL held, before the trace.
    explicit HitArrays(const Shape& rays);
    // Fills them from the hits, without the GIL (the buffers are written through raw pointers).
    void fill(const std::vector<RayHit>& hits, const TraceScene& scene);
    py::dict toDict() const;

private:
    py::array_t<float> tHit_;
    py::array_t<std::uint32_t> primitiveIds_;
    py::array_t<float> uvs_, normals_;
    // Their buffers, taken with the GIL held.
    float* tData_ = nullptr;
    std::uint32_t* idData_ = nullptr;
    float* uvData_ = nullptr;
    float* normalData_ = nullptr;
    std::size_t count_ = 0;
};

}  // namespace dacrt::python
