// Pieces of the _batchcol extension module, each registered by its own file.
#pragma once

#include "batchcol/shapes.hpp"

#include <pybind11/pybind11.h>

#include <memory>

namespace batchcol::python {

namespace py = pybind11;

/// The Python ShapeTable. `busy` counts engine calls running on it with the GIL released: add() refuses to grow the
/// table (and so move its shapes) while the engine reads them from another thread.
struct TableHolder {
  std::shared_ptr<ShapeTable> table = std::make_shared<ShapeTable>();
  int busy = 0;
};

/// Marks a table busy for its lifetime. Construct and destroy it with the GIL held (before a gil_scoped_release).
class TableUse {
 public:
  explicit TableUse(TableHolder& holder) : holder_(holder) { ++holder_.busy; }
  ~TableUse() { --holder_.busy; }
  TableUse(const TableUse&) = delete;
  TableUse& operator=(const TableUse&) = delete;

 private:
  TableHolder& holder_;
};

void register_shapes(py::module_& m);
void register_collide(py::module_& m);
void register_scene(py::module_& m);
void register_io(py::module_& m);
void register_derivatives(py::module_& m);

}  // namespace batchcol::python
