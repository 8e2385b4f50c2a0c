#include "numpy_arrays.hpp"

#include <cstdint>

#include <pybind11/pybind11.h>

#include <dacrt/errors.hpp>

namespace dacrt::python {

namespace {

std::string text(const py::handle& object) { return py::str(object).cast<std::string>(); }

std::string shapeText(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

// The array of `object`, its dtype T: an ndarray as it is (refused with another dtype), any
// other object converted by numpy.asarray to T.
template <typename T>
py::array ndarrayOf(const py::handle& object, const std::string& name) {
    const py::dtype expected = py::dtype::of<T>();
    if (py::isinstance<py::array>(object)) {
        py::array a = py::reinterpret_borrow<py::array>(object);
        if (!a.dtype().equal(expected))
            throw InputError(name + ": dtype " + text(a.dtype()) + ", expected " + text(expected) + " (convert with " +
                             name + ".astype(numpy." + text(expected) + "))");
        return a;
    }
    return py::module_::import("numpy").attr("asarray")(object, expected);
}

}  // namespace

template <typename T>
Contiguous<T> valuesOf(const py::handle& object, const std::string& name) {
    const py::array a = ndarrayOf<T>(object, name);
    // Copies only an array that is not C-contiguous (a view with strides, a transposed array);
    // numpy's own error (no memory for the copy) is raised as it is.
    return Contiguous<T>(a);
}

template <typename T>
Contiguous<T> rowsOf(const py::handle& object, const std::string& name, py::ssize_t width) {
    const py::array a = ndarrayOf<T>(object, name);
    if (a.ndim() < 1 || a.shape(a.ndim() - 1) != width)
        throw InputError(name + ": shape " + shapeText(a) + ", expected (..., " + std::to_string(width) + ")");
    return valuesOf<T>(a, name);
}

Shape leadingShape(const py::array& a) { return Shape(a.shape(), a.shape() + a.ndim() - 1); }

std::size_t elementCount(const Shape& shape) {
    std::size_t n = 1;
    for (py::ssize_t extent : shape) n *= std::size_t(extent);
    return n;
}

template <typename T>
py::array_t<T> arrayOf(Shape shape, py::ssize_t width) {
    if (width != 0) shape.push_back(width);
    return py::array_t<T>(shape);
}

SegmentBound segmentBoundOf(const py::handle& object, const std::string& name, const Shape& rays, float unbounded) {
    SegmentBound bound;
    const bool number = py::isinstance<py::float_>(object) || py::isinstance<py::int_>(object);
    if (!number) bound.array = valuesOf<float>(object, name);
    if (number || bound.array.ndim() == 0) {  // one value for every ray
        const float value = number ? object.cast<float>() : *bound.array.data();
        if (!(value == unbounded)) {  // NaN too: the library names it
            bound.filled.assign(elementCount(rays), value);
            bound.values = bound.filled;
        }
        return bound;
    }
    if (Shape(bound.array.shape(), bound.array.shape() + bound.array.ndim()) != rays)
        throw InputError(name + ": shape " + shapeText(bound.array) + ", expected a number or the rays' shape without "
                         "their last axis");
    bound.values = spanOf(bound.array);
    return bound;
}

template Contiguous<float> rowsOf<float>(const py::handle&, const std::string&, py::ssize_t);
template Contiguous<std::uint32_t> rowsOf<std::uint32_t>(const py::handle&, const std::string&, py::ssize_t);
template Contiguous<bool> valuesOf<bool>(const py::handle&, const std::string&);
template py::array_t<float> arrayOf<float>(Shape, py::ssize_t);
template py::array_t<std::uint32_t> arrayOf<std::uint32_t>(Shape, py::ssize_t);
template py::array_t<bool> arrayOf<bool>(Shape, py::ssize_t);

}  // namespace dacrt::python
