#include "arrays.hpp"

#include <cstring>
#include <limits>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

/// `obj` as a numpy array: arrays as they are, anything else (lists, tuples) converted to float64.
py::array as_float_array(const py::handle& obj, const char* name) {
  if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
  try {
    return py::module_::import("numpy").attr("asarray")(obj, "dtype"_a = "float64");
  } catch (py::error_already_set& e) {
    throw ArgumentError(std::string(name) + " must be a float64 array: " + e.what());
  }
}

/// Checks dtype and shape of an (n, columns) pose argument.
py::array checked_rows(const py::handle& obj, const char* name, std::size_t n, int columns) {
  py::array a = as_float_array(obj, name);
  if (!a.dtype().equal(py::dtype::of<double>()))
    throw ArgumentError(std::string(name) + " must be a float64 array, got dtype " + dtype_text(a) +
                        " (batchcol does not change precision silently: convert with .astype(numpy.float64))");
  const std::string want = "(N, " + std::to_string(columns) + ")";
  if (a.ndim() != 2 || a.shape(1) != columns)
    throw ArgumentError(std::string(name) + " must have shape " + want + ", got " + shape_text(a));
  if (static_cast<std::size_t>(a.shape(0)) != n)
    throw ArgumentError(std::string(name) + " has " + std::to_string(a.shape(0)) + " rows, expected " +
                        std::to_string(n) + " (one per pair)");
  return a;
}

/// Pointers to the columns of `a` when each is contiguous and aligned (the engine's structure-of-arrays layout),
/// else copies `a` into a (columns, n) C-contiguous array first (or refuses when copies are not allowed).
void column_pointers(const py::handle& obj, const char* name, std::size_t n, int columns, bool allow_copy,
                     KeepAlive& keep, const double** out) {
  py::array a = checked_rows(obj, name, n, columns);
  const auto* base = static_cast<const char*>(a.data());
  const py::ssize_t row_stride = a.strides(0), column_stride = a.strides(1);
  const bool unit_rows = n <= 1 || row_stride == static_cast<py::ssize_t>(sizeof(double));
  const bool aligned = reinterpret_cast<std::uintptr_t>(base) % alignof(double) == 0 &&
                       column_stride % static_cast<py::ssize_t>(alignof(double)) == 0;
  if (unit_rows && aligned) {
    for (int c = 0; c < columns; ++c) out[c] = reinterpret_cast<const double*>(base + c * column_stride);
    return;
  }
  if (!allow_copy)
    throw ArgumentError(std::string(name) + " cannot be viewed without a copy: batchcol reads each column as one "
                        "contiguous float64 array (structure of arrays); pass numpy.asfortranarray(" + name +
                        ") or the transpose of a (" + std::to_string(columns) + ", N) C-contiguous array, or "
                        "copy=True");
  py::array_t<double, py::array::c_style> soa({static_cast<py::ssize_t>(columns), static_cast<py::ssize_t>(n)});
  double* dst = soa.mutable_data();
  {
    // One pass over the rows (a C-ordered array is read sequentially), with the GIL released: the transpose is
    // the whole cost of a copied argument.
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) {
      const char* row = base + static_cast<py::ssize_t>(i) * row_stride;
      for (int c = 0; c < columns; ++c) {
        double v;  // memcpy: the source may be unaligned
        std::memcpy(&v, row + c * column_stride, sizeof v);
        dst[static_cast<std::size_t>(c) * n + i] = v;
      }
    }
  }
  for (int c = 0; c < columns; ++c) out[c] = dst + static_cast<std::size_t>(c) * n;
  keep.push_back(std::move(soa));
}

}  // namespace

std::size_t rows_of(const py::handle& obj, const char* name, int columns) {
  py::array a = as_float_array(obj, name);
  if (a.ndim() != 2 || a.shape(1) != columns)
    throw ArgumentError(std::string(name) + " must have shape (N, " + std::to_string(columns) + "), got " +
                        shape_text(a));
  return static_cast<std::size_t>(a.shape(0));
}

Vec3View vec3_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy, KeepAlive& keep) {
  const double* p[3];
  column_pointers(obj, name, n, 3, allow_copy, keep, p);
  return {{p[0], n}, {p[1], n}, {p[2], n}};
}

QuatView quat_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy, KeepAlive& keep) {
  const double* p[4];
  column_pointers(obj, name, n, 4, allow_copy, keep, p);
  return {{p[0], n}, {p[1], n}, {p[2], n}, {p[3], n}};
}

ConstSpan<std::uint32_t> index_input(const py::handle& obj, const char* name, std::size_t n, bool allow_copy,
                                     KeepAlive& keep) {
  const py::module_ np = py::module_::import("numpy");
  if (py::isinstance<py::int_>(obj) && !py::isinstance<py::bool_>(obj)) {
    const long long v = obj.cast<long long>();
    if (v < 0 || v > std::numeric_limits<std::uint32_t>::max())
      throw ArgumentError(std::string(name) + " = " + std::to_string(v) + " is not a valid shape index");
    py::array_t<std::uint32_t> filled(static_cast<py::ssize_t>(n));
    std::fill_n(filled.mutable_data(), n, static_cast<std::uint32_t>(v));
    keep.push_back(filled);
    return {filled.data(), n};
  }
  py::array a = py::isinstance<py::array>(obj) ? py::reinterpret_borrow<py::array>(obj)
                                                : py::array(np.attr("asarray")(obj));
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw ArgumentError(std::string(name) + " must be an array of integer shape indices, got dtype " + dtype_text(a));
  if (a.ndim() != 1)
    throw ArgumentError(std::string(name) + " must have shape (N,), got " + shape_text(a));
  if (static_cast<std::size_t>(a.shape(0)) != n)
    throw ArgumentError(std::string(name) + " has " + std::to_string(a.shape(0)) + " entries, expected " +
                        std::to_string(n) + " (one per pair)");
  const bool viewable = a.dtype().equal(py::dtype::of<std::uint32_t>()) &&
                        (n <= 1 || a.strides(0) == static_cast<py::ssize_t>(sizeof(std::uint32_t))) &&
                        reinterpret_cast<std::uintptr_t>(a.data()) % alignof(std::uint32_t) == 0;
  if (viewable) return {static_cast<const std::uint32_t*>(a.data()), n};
  if (!allow_copy)
    throw ArgumentError(std::string(name) + " cannot be viewed without a copy: pass a contiguous uint32 array or "
                        "copy=True (got dtype " + dtype_text(a) + ")");
  if (n > 0) {
    const auto lowest = py::int_(a.attr("min")()).cast<long long>();
    if (lowest < 0) {
      const auto at = py::int_(a.attr("argmin")()).cast<long long>();
      throw ArgumentError(std::string(name) + "[" + std::to_string(at) + "] = " + std::to_string(lowest) +
                          " is negative (shape indices are >= 0)");
    }
    const auto highest = py::int_(a.attr("max")()).cast<unsigned long long>();
    if (highest > std::numeric_limits<std::uint32_t>::max()) {
      const auto at = py::int_(a.attr("argmax")()).cast<long long>();
      throw ArgumentError(std::string(name) + "[" + std::to_string(at) + "] = " + std::to_string(highest) +
                          " is beyond the largest shape index 4294967295");
    }
  }
  py::array converted = np.attr("ascontiguousarray")(a, "dtype"_a = "uint32");
  keep.push_back(converted);
  return {static_cast<const std::uint32_t*>(converted.data()), n};
}

py::array view_bool_array(const std::uint8_t* data, std::size_t n, const py::handle& owner) {
  static_assert(sizeof(bool) == 1, "numpy bools are bytes");
  return py::array(py::dtype("bool"), {static_cast<py::ssize_t>(n)}, {py::ssize_t{1}}, n == 0 ? nullptr : data,
                   owner);
}

py::object view_xyz(const Vec3Array& v, const py::handle& owner) {
  const py::object xyz = py::module_::import("batchcol._batchcol").attr("XYZ");
  return xyz(view_array(v.x.data(), v.size(), owner), view_array(v.y.data(), v.size(), owner),
             view_array(v.z.data(), v.size(), owner));
}

py::array_t<double, py::array::c_style> float_rows(const py::handle& obj, const char* name, std::size_t n,
                                                   int columns) {
  py::array a = checked_rows(obj, name, n, columns);
  return py::array_t<double, py::array::c_style>::ensure(a);
}

}  // namespace batchcol::python
