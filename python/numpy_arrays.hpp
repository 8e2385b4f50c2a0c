#pragma once
// Numpy arrays as the module reads and writes them: the dtype and shape checked with messages
// that name the argument (dacrt::InputError, raised as dacrt.InputError), the caller's data
// read in place where it is C-contiguous and copied once where it is not.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <pybind11/numpy.h>

namespace dacrt::python {

namespace py = pybind11;

using Shape = std::vector<py::ssize_t>;

template <typename T>
using Contiguous = py::array_t<T, py::array::c_style>;

// `object` as a C-contiguous array of T (float, std::uint32_t or bool) whose last axis holds
// `width` values: the caller's own array where it is one already (no copy), a contiguous copy
// of another layout, a list or other sequence converted. Throws InputError naming `name` on
// another dtype (an array is never converted: a float64 or int64 array would be rounded or
// wrapped silently) or another last axis.
template <typename T>
Contiguous<T> rowsOf(const py::handle& object, const std::string& name, py::ssize_t width);

// The same for an array of any shape (width is not checked).
template <typename T>
Contiguous<T> valuesOf(const py::handle& object, const std::string& name);

// The shape of `a` without its last axis.
Shape leadingShape(const py::array& a);

// The number of elements of an array of `shape`.
std::size_t elementCount(const Shape& shape);

// A fresh array of `shape`, with a last axis of `width` more where width is not 0.
template <typename T>
py::array_t<T> arrayOf(Shape shape, py::ssize_t width = 0);

template <typename T>
std::span<const T> spanOf(const Contiguous<T>& a) {
    return {a.data(), std::size_t(a.size())};
}

// A ray's segment bound, tmin or tmax: one number for every ray, or an array of float32 shaped
// as the rays without their last axis. `values` is empty for the number `unbounded` (the
// library's default: 0 for tmin, +inf for tmax), which then costs nothing per ray.
struct SegmentBound {
    Contiguous<float> array;   // the caller's array, where one was given
    std::vector<float> filled; // one number for every ray
    std::span<const float> values;
};
SegmentBound segmentBoundOf(const py::handle& object, const std::string& name, const Shape& rays, float unbounded);

}  // namespace dacrt::python
