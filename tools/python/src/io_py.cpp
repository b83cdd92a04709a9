// Batch files (the CLI's JSON format) and mesh points, so Python runs the same batches as `batchcol query`.
#include "arrays.hpp"
#include "module.hpp"

#include "batchcol/io.hpp"

#include <pybind11/stl.h>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

/// An (n, columns) float64 array in Fortran order (each column contiguous, the layout collide() views) holding
/// the component arrays; a copy.
py::array columns_array(std::initializer_list<const std::vector<double>*> columns) {
  const std::size_t n = (*columns.begin())->size();
  const auto cols = static_cast<py::ssize_t>(columns.size());
  py::array_t<double, py::array::f_style> a({static_cast<py::ssize_t>(n), cols});
  double* dst = a.mutable_data();
  for (const auto* c : columns) dst = std::copy(c->begin(), c->end(), dst);
  return a;
}

}  // namespace

void register_io(py::module_& m) {
  m.def(
      "load_batch_file",
      [](const std::string& path) {
        BatchFile f = load_batch_file(path);
        auto table = std::make_shared<TableHolder>();
        *table->table = std::move(f.shapes);
        const PairBatch& b = f.pairs;
        py::dict options;
        if (f.query) options["level"] = to_string(*f.query);
        if (f.solver) options["solver"] = to_string(*f.solver);
        if (f.tolerance) options["tolerance"] = *f.tolerance;
        if (f.precision) options["precision"] = *f.precision == Precision::float32 ? "float" : "double";
        if (f.margin) options["margin"] = *f.margin;
        return py::dict("shapes"_a = table, "shape_a"_a = py::array_t<std::uint32_t>(py::cast(b.shape_a)),
                        "shape_b"_a = py::array_t<std::uint32_t>(py::cast(b.shape_b)),
                        "translation_a"_a = columns_array({&b.translation_a.x, &b.translation_a.y, &b.translation_a.z}),
                        "quaternion_a"_a = columns_array({&b.rotation_a.w, &b.rotation_a.x, &b.rotation_a.y, &b.rotation_a.z}),
                        "translation_b"_a = columns_array({&b.translation_b.x, &b.translation_b.y, &b.translation_b.z}),
                        "quaternion_b"_a = columns_array({&b.rotation_b.w, &b.rotation_b.x, &b.rotation_b.y, &b.rotation_b.z}),
                        "options"_a = options);
      },
      "path"_a,
      "reads a batch file: dict of shapes (ShapeTable), the pair arrays (Fortran order: collide() views them) "
      "and the file's options (keyword arguments of collide())");
  m.def("load_mesh_points", [](const std::string& path) {
    const auto points = load_mesh_points(path);
    py::array_t<double> a({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
    for (std::size_t i = 0; i < points.size(); ++i)
      for (int c = 0; c < 3; ++c) a.mutable_at(i, c) = points[i][c];
    return a;
  }, "path"_a, "the vertices of a mesh file as an (M, 3) array");
}

}  // namespace batchcol::python
