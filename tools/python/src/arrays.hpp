// NumPy arrays in and out of the engine. Inputs are viewed when their layout is the engine's (one contiguous
// array per component, i.e. every column of an (N, 3) / (N, 4) float64 array has unit stride: Fortran order, or
// the transpose of a (3, N) C-contiguous array); otherwise they are copied once into that layout, or refused when
// the caller passed copy=False. Outputs are arrays over the engine's std::vector buffers whose base object is the
// Python object that owns those buffers, so the buffers live as long as any array over them.
#pragma once

#include "batchcol/batch.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

namespace batchcol::python {

namespace py = pybind11;

/// Raised as ValueError: bad arguments (the engine's InputError is translated to the same type).
struct ArgumentError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Arrays a call allocated (copies, converted indices): kept alive until the engine returns.
using KeepAlive = std::vector<py::object>;

/// The number of rows of `obj` viewed as a (N, columns) float64 array (for inferring N before the other checks).
std::size_t rows_of(const py::handle& obj, const char* name, int columns);

/// Per-component views of an (n, 3) / (n, 4) float64 argument named `name` (see the file comment).
Vec3View vec3_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy, KeepAlive& keep);
QuatView quat_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy, KeepAlive& keep);
/// A view of n shape indices: a 1-D uint32 contiguous array is viewed; other integer arrays are range-checked
/// and converted (a copy); a Python int is repeated n times.
ConstSpan<std::uint32_t> index_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy,
                                     KeepAlive& keep);

/// A 1-D array over `data` (n entries) that keeps `owner` alive; no copy.
template <class T>
py::array view_array(const T* data, std::size_t n, const py::handle& owner) {
  return py::array(py::dtype::of<T>(), {static_cast<py::ssize_t>(n)}, {static_cast<py::ssize_t>(sizeof(T))},
                   n == 0 ? nullptr : data, owner);
}
/// A 1-D bool array over a buffer of 0/1 bytes that keeps `owner` alive; no copy.
py::array view_bool_array(const std::uint8_t* data, std::size_t n, const py::handle& owner);
/// The three components of a Vec3Array as the namedtuple batchcol.XYZ(x, y, z) of 1-D views; no copy.
py::object view_xyz(const Vec3Array& v, const py::handle& owner);

/// The argument `obj` as a float64 numpy array of shape (n, 3), copied (for the few places that read values
/// element by element: scene objects, hull points).
py::array_t<double, py::array::c_style> float_rows(const py::handle& obj, const char* name, std::size_t n,
                                                   int columns);

}  // namespace batchcol::python
