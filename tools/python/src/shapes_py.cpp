// Shapes and the shape table. A table pickles as the exact fields of its shapes (hulls with their faces and
// adjacency), not as factory calls: re-running qhull could order the vertices differently and change results in
// the last bits, and a Dask job must give the same bits as a single-process run.
#include "arrays.hpp"
#include "module.hpp"

#include "batchcol/io.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

constexpr const char* kStateTag = "batchcol.ShapeTable";
constexpr int kStateVersion = 1;

ShapeType type_from_name(const std::string& name) {
  for (int t = 0; t < kShapeTypeCount; ++t)
    if (name == to_string(static_cast<ShapeType>(t))) return static_cast<ShapeType>(t);
  throw ArgumentError("ShapeTable state: unknown shape type '" + name + "'");
}

std::vector<Eigen::Vector3d> points_of(const py::handle& obj, const char* name) {
  const auto a = float_rows(obj, name, rows_of(obj, name, 3), 3);
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(a.shape(0)));
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {a.at(i, 0), a.at(i, 1), a.at(i, 2)};
  return points;
}

template <class T, int Columns>
py::array_t<T> rows_array(const std::vector<T>& flat) {
  py::array_t<T> a({static_cast<py::ssize_t>(flat.size() / Columns), static_cast<py::ssize_t>(Columns)});
  std::copy(flat.begin(), flat.end(), a.mutable_data());
  return a;
}

py::tuple hull_state(const ConvexHull& h) {
  std::vector<double> vertices, normals;
  std::vector<std::uint32_t> faces;
  for (const auto& v : h.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
  for (const auto& n : h.face_normals) normals.insert(normals.end(), {n.x(), n.y(), n.z()});
  for (const auto& f : h.faces) faces.insert(faces.end(), f.begin(), f.end());
  return py::make_tuple(rows_array<double, 3>(vertices), rows_array<std::uint32_t, 3>(faces),
                        rows_array<double, 3>(normals), py::array_t<std::uint32_t>(py::cast(h.neighbor_offsets)),
                        py::array_t<std::uint32_t>(py::cast(h.neighbors)), h.centroid, h.radius);
}

/// Rebuilds a hull from hull_state(), checking every index so that a corrupt pickle cannot reach the kernels.
std::shared_ptr<const ConvexHull> hull_from_state(const py::tuple& t) {
  if (t.size() != 7) throw ArgumentError("ShapeTable state: a hull has 7 fields");
  auto h = std::make_shared<ConvexHull>();
  h->vertices = points_of(t[0], "hull vertices");
  const auto faces = py::array_t<std::uint32_t, py::array::c_style | py::array::forcecast>::ensure(t[1]);
  const auto normals = points_of(t[2], "hull face normals");
  h->neighbor_offsets = t[3].cast<std::vector<std::uint32_t>>();
  h->neighbors = t[4].cast<std::vector<std::uint32_t>>();
  h->centroid = t[5].cast<Eigen::Vector3d>();
  h->radius = t[6].cast<double>();
  const std::size_t nv = h->vertices.size();
  bool ok = faces && faces.ndim() == 2 && faces.shape(1) == 3 &&
            static_cast<std::size_t>(faces.shape(0)) == normals.size() && nv >= 4 &&
            h->neighbor_offsets.size() == nv + 1 && h->neighbor_offsets.front() == 0 &&
            h->neighbor_offsets.back() == h->neighbors.size() && h->centroid.allFinite() && std::isfinite(h->radius);
  for (std::size_t i = 0; ok && i < nv; ++i)
    ok = h->vertices[i].allFinite() && h->neighbor_offsets[i] <= h->neighbor_offsets[i + 1];
  for (const auto v : h->neighbors) ok = ok && v < nv;
  if (!ok) throw ArgumentError("ShapeTable state: inconsistent convex hull");
  for (py::ssize_t f = 0; f < faces.shape(0); ++f) {
    std::array<std::uint32_t, 3> face{faces.at(f, 0), faces.at(f, 1), faces.at(f, 2)};
    for (const auto v : face)
      if (v >= nv) throw ArgumentError("ShapeTable state: hull face index out of range");
    h->faces.push_back(face);
    h->face_normals.push_back(normals[static_cast<std::size_t>(f)]);
  }
  return h;
}

py::tuple shape_state(const Shape& s) {
  py::object triangle = py::none(), hull = py::none();
  if (s.type == ShapeType::triangle) triangle = py::make_tuple(s.triangle[0], s.triangle[1], s.triangle[2]);
  if (s.type == ShapeType::convex) hull = hull_state(*s.hull);
  return py::make_tuple(to_string(s.type), s.size, s.offset, s.inflation, triangle, hull);
}

/// The shape of shape_state(): validated by its factory, then given the stored fields bit for bit.
Shape shape_from_state(const py::handle& obj) {
  const auto t = obj.cast<py::tuple>();
  if (t.size() != 6) throw ArgumentError("ShapeTable state: a shape has 6 fields");
  const ShapeType type = type_from_name(t[0].cast<std::string>());
  const auto size = t[1].cast<Eigen::Vector3d>();
  const double offset = t[2].cast<double>();
  Shape s;
  switch (type) {
    case ShapeType::sphere: s = Shape::sphere(size.x()); break;
    case ShapeType::capsule: s = Shape::capsule(size.x(), size.y()); break;
    case ShapeType::box: s = Shape::box(size); break;
    case ShapeType::cylinder: s = Shape::cylinder(size.x(), size.y()); break;
    case ShapeType::cone: s = Shape::cone(size.x(), size.y()); break;
    case ShapeType::ellipsoid: s = Shape::ellipsoid(size.x(), size.y(), size.z()); break;
    case ShapeType::convex: s = Shape::convex(hull_from_state(t[5].cast<py::tuple>())); break;
    case ShapeType::triangle: {
      const auto v = t[4].cast<std::array<Eigen::Vector3d, 3>>();
      s = Shape::triangle_shape(v[0], v[1], v[2]);
      break;
    }
    case ShapeType::halfspace:
      s = Shape::halfspace(size, offset);
      if (std::abs(size.norm() - 1.0) > 1e-12) throw ArgumentError("ShapeTable state: halfspace normal is not unit");
      break;
  }
  s = s.inflated(t[3].cast<double>());
  if (type != ShapeType::convex && type != ShapeType::triangle) s.size = size, s.offset = offset;
  return s;
}

std::string repr(const Shape& s) {
  std::string r = std::string("Shape.") + to_string(s.type) + "(";
  if (s.type == ShapeType::convex) r += std::to_string(s.hull->vertices.size()) + " hull vertices";
  else if (s.type != ShapeType::triangle)
    r += "size=(" + std::to_string(s.size.x()) + ", " + std::to_string(s.size.y()) + ", " +
         std::to_string(s.size.z()) + ")";
  if (s.inflation > 0) r += ", inflation=" + std::to_string(s.inflation);
  return r + ")";
}

}  // namespace

void register_shapes(py::module_& m) {
  py::class_<Shape>(m, "Shape", "One convex shape (metres; capsule, cylinder and cone axes are local z).")
      .def_static("sphere", &Shape::sphere, "radius"_a)
      .def_static("capsule", &Shape::capsule, "radius"_a, "half_length"_a)
      .def_static("box", py::overload_cast<double, double, double>(&Shape::box), "hx"_a, "hy"_a, "hz"_a)
      .def_static("cylinder", &Shape::cylinder, "radius"_a, "half_length"_a)
      .def_static("cone", &Shape::cone, "radius"_a, "half_length"_a, "apex at +half_length")
      .def_static("ellipsoid", &Shape::ellipsoid, "rx"_a, "ry"_a, "rz"_a)
      .def_static(
          "convex", [](const py::handle& points) { return Shape::convex(points_of(points, "points")); }, "points"_a,
          "convex hull (qhull) of an (M, 3) array of points")
      .def_static(
          "mesh",
          [](const std::string& path) { return Shape::convex(compute_convex_hull(load_mesh_points(path), path)); },
          "path"_a, "convex hull of a mesh file (.obj, .stl, .ply, .dae)")
      .def_static("triangle", &Shape::triangle_shape, "a"_a, "b"_a, "c"_a)
      .def_static("halfspace", &Shape::halfspace, "normal"_a, "offset"_a, "the solid {x : normal.x <= offset}")
      .def("inflated", &Shape::inflated, "radius"_a, "a copy with a swept-sphere radius added")
      .def_property_readonly("type", [](const Shape& s) { return std::string(to_string(s.type)); })
      .def_property_readonly("size", [](const Shape& s) { return s.size; })
      .def_property_readonly("offset", [](const Shape& s) { return s.offset; })
      .def_property_readonly("inflation", [](const Shape& s) { return s.inflation; })
      .def_property_readonly("bounding_radius", &Shape::bounding_radius)
      .def_property_readonly("vertices",
                             [](const Shape& s) -> py::object {
                               if (s.type == ShapeType::triangle) return py::cast(s.triangle);
                               if (s.type == ShapeType::convex) return hull_state(*s.hull)[0];
                               return py::none();
                             })
      .def(py::pickle([](const Shape& s) { return shape_state(s); },
                      [](const py::tuple& t) { return shape_from_state(t); }))
      .def("__repr__", &repr);

  py::class_<TableHolder, std::shared_ptr<TableHolder>>(m, "ShapeTable",
                                                        "Stores each shape once; pairs refer to shapes by index.")
      .def(py::init<>())
      .def(
          "add",
          [](TableHolder& h, const Shape& s) {
            if (h.busy > 0) throw std::runtime_error("ShapeTable.add: the table is in use by a running collide()");
            return h.table->add(s);
          },
          "shape"_a, "appends a shape and returns its index")
      .def("__len__", [](const TableHolder& h) { return h.table->size(); })
      .def("__getitem__",
           [](const TableHolder& h, std::size_t i) {
             if (i >= h.table->size()) throw py::index_error("shape index " + std::to_string(i) + " out of range");
             return (*h.table)[i];
           })
      .def(py::pickle(
          [](const TableHolder& h) {
            py::list shapes;
            for (const Shape& s : h.table->shapes()) shapes.append(shape_state(s));
            return py::make_tuple(kStateTag, kStateVersion, shapes);
          },
          [](const py::tuple& t) {
            if (t.size() != 3 || t[0].cast<std::string>() != kStateTag || t[1].cast<int>() != kStateVersion)
              throw ArgumentError("ShapeTable state: not a batchcol.ShapeTable pickle of version 1");
            auto h = std::make_shared<TableHolder>();
            for (const auto& s : t[2].cast<py::list>()) h->table->add(shape_from_state(s));
            return h;
          }))
      .def("__repr__", [](const TableHolder& h) { return "ShapeTable(" + std::to_string(h.table->size()) + " shapes)"; });
}

}  // namespace batchcol::python
