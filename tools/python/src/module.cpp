// The compiled part of the `batchcol` Python package (see tools/python/batchcol/__init__.py for the public names).
#include "arrays.hpp"
#include "module.hpp"

#include "batchcol/errors.hpp"

PYBIND11_MODULE(_batchcol, m) {
  namespace py = pybind11;
  using namespace batchcol::python;
  using namespace pybind11::literals;
  m.doc() = "batchcol: batched convex collision queries on NumPy arrays (compiled part)";
  // Bad input is a ValueError with the engine's message (it names the argument or field).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const batchcol::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const ArgumentError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  // Three components of a vector field, each a 1-D array over the engine's buffers (the engine stores x, y and z
  // as separate arrays, so an (N, 3) array would be a copy: numpy.stack(v, axis=1) makes one when wanted).
  m.attr("XYZ") = py::module_::import("collections").attr("namedtuple")("XYZ", "x y z", "module"_a = "batchcol._batchcol");
  register_shapes(m);
  register_collide(m);
  register_scene(m);
  register_io(m);
  register_derivatives(m);
}
