// batchcol.collide() on NumPy arrays and the Results object whose arrays are views of the engine's buffers.
#include "arrays.hpp"
#include "collide_py.hpp"
#include "module.hpp"

#include "batchcol/io.hpp"

#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

std::string pose_text(const double* v, int n) {
  std::ostringstream s;
  s.precision(17);
  s << "[";
  for (int c = 0; c < n; ++c) s << (c ? ", " : "") << v[c];
  return s.str() + "]";
}

/// Why pair i was rejected, with the engine's rules (types.hpp: kUnitTolerance), naming the argument.
std::string invalid_reason(const ShapeTable& shapes, const PairBatchView& b, std::size_t i) {
  const std::string at = "[" + std::to_string(i) + "]";
  const ConstSpan<std::uint32_t>* index[2] = {&b.shape_a, &b.shape_b};
  const Vec3View* t[2] = {&b.translation_a, &b.translation_b};
  const QuatView* q[2] = {&b.rotation_a, &b.rotation_b};
  for (int s = 0; s < 2; ++s) {
    const char side = s == 0 ? 'a' : 'b';
    if ((*index[s])[i] >= shapes.size())
      return std::string("shape_") + side + at + " = " + std::to_string((*index[s])[i]) + " is out of range (the table "
             "has " + std::to_string(shapes.size()) + " shapes)";
    const double tv[3] = {t[s]->x[i], t[s]->y[i], t[s]->z[i]};
    if (!(*t[s])[i].allFinite()) return std::string("translation_") + side + at + " = " + pose_text(tv, 3) + " is not finite";
    const double qv[4] = {q[s]->w[i], q[s]->x[i], q[s]->y[i], q[s]->z[i]};
    if (!is_unit_quaternion((*q[s])[i]))
      return std::string("quaternion_") + side + at + " = " + pose_text(qv, 4) + " is not a finite unit quaternion "
             "[w, x, y, z] (norm within 1e-6 of 1)";
  }
  return "pair " + std::to_string(i) + " has invalid input";
}


/// Raw timings of the C++ collide() on the same arrays, for bench/python/overhead.py (not public API): on the
/// view of the caller's memory itself (same pages: the binding's overhead alone), or on a PairBatch copy.
std::vector<double> cpp_collide_seconds(const TableHolder& table, const PairBatchView& v, const QueryOptions& o,
                                        int repeats, bool reuse_results, bool copy_to_batch) {
  const PairBatch batch = copy_to_batch ? batch_copy(v) : PairBatch();
  std::vector<double> seconds;
  PairResults reused;
  for (int k = 0; k < repeats; ++k) {
    PairResults fresh;
    PairResults& out = reuse_results ? reused : fresh;
    const auto start = std::chrono::steady_clock::now();
    if (copy_to_batch) collide(*table.table, batch, o, out);
    else collide(*table.table, v, o, out);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return seconds;
}

}  // namespace

void raise_invalid(const ShapeTable& shapes, const PairBatchView& b, const PairResults& r) {
  // memchr: the common case (no invalid pair) costs one vectorised pass over one byte per pair.
  static_assert(sizeof(Status) == 1, "statuses are bytes");
  const auto* status = reinterpret_cast<const unsigned char*>(r.status.data());
  const void* hit = r.size() == 0 ? nullptr : std::memchr(status, static_cast<int>(Status::invalid_input), r.size());
  if (hit == nullptr) return;
  const auto first = static_cast<std::size_t>(static_cast<const unsigned char*>(hit) - status);
  std::size_t count = 0;
  for (std::size_t i = first; i < r.size(); ++i) count += r.status[i] == Status::invalid_input;
  throw ArgumentError(invalid_reason(shapes, b, first) + " (" + std::to_string(count) + " of " +
                      std::to_string(r.size()) + " pairs have invalid input; invalid='status' reports them as "
                      "per-pair statuses instead of this error)");
}

PairBatch batch_copy(const PairBatchView& v) {
  PairBatch b;
  b.shape_a.assign(v.shape_a.data(), v.shape_a.data() + v.size());
  b.shape_b.assign(v.shape_b.data(), v.shape_b.data() + v.size());
  const auto copy = [](const ConstSpan<double>& s, std::vector<double>& d) { d.assign(s.data(), s.data() + s.size()); };
  for (auto [from, to] : {std::pair{&v.translation_a, &b.translation_a}, {&v.translation_b, &b.translation_b}})
    copy(from->x, to->x), copy(from->y, to->y), copy(from->z, to->z);
  for (auto [from, to] : {std::pair{&v.rotation_a, &b.rotation_a}, {&v.rotation_b, &b.rotation_b}})
    copy(from->w, to->w), copy(from->x, to->x), copy(from->y, to->y), copy(from->z, to->z);
  return b;
}

QueryOptions options_from(const std::string& level, const std::string& solver, const std::string& precision,
                          double tolerance, double relative_tolerance, double margin, int max_iterations,
                          int epa_max_iterations, bool closed_forms, int threads, const std::string& isa) {
  QueryOptions o;
  o.level = parse_query_level(level);
  o.solver = parse_solver(solver);
  o.precision = parse_precision(precision);
  o.tolerance = tolerance;
  o.relative_tolerance = relative_tolerance;
  o.margin = margin;
  o.max_iterations = max_iterations;
  o.epa_max_iterations = epa_max_iterations;
  o.closed_forms = closed_forms;
  o.threads = threads;
  o.isa = parse_instruction_set(isa);
  validate(o);
  return o;
}

PairBatchView batch_input(const py::handle& shape_a, const py::handle& shape_b, const py::handle& translation_a,
                          const py::handle& quaternion_a, const py::handle& translation_b,
                          const py::handle& quaternion_b, const py::handle& warm_start, bool copy, KeepAlive& keep) {
  const std::size_t n = rows_of(translation_a, "translation_a", 3);
  PairBatchView v;
  v.shape_a = index_input(shape_a, "shape_a", n, copy, keep);
  v.shape_b = index_input(shape_b, "shape_b", n, copy, keep);
  v.translation_a = vec3_input(translation_a, "translation_a", n, copy, keep);
  v.translation_b = vec3_input(translation_b, "translation_b", n, copy, keep);
  v.rotation_a = quat_input(quaternion_a, "quaternion_a", n, copy, keep);
  v.rotation_b = quat_input(quaternion_b, "quaternion_b", n, copy, keep);
  if (!warm_start.is_none()) v.warm_start = vec3_input(warm_start, "warm_start", n, copy, keep);
  return v;
}

void register_collide(py::module_& m) {
  py::class_<ResultsHolder, std::shared_ptr<ResultsHolder>>(
      m, "Results",
      "Per-pair results in input order. Every array is a view of the engine's buffers (no copy) and keeps this "
      "object alive; arrays the query level does not compute are empty.")
      .def("__len__", [](const ResultsHolder& h) { return h.results.size(); })
      .def_property_readonly("level", [](const ResultsHolder& h) { return std::string(to_string(h.level)); })
      .def_property_readonly("status", [](py::object self) {
        const auto& r = self.cast<ResultsHolder&>().results;
        static_assert(sizeof(Status) == 1, "statuses are bytes");
        return view_array(reinterpret_cast<const std::uint8_t*>(r.status.data()), r.size(), self);
      }, "uint8 codes: 0 converged, 1 max_iterations, 2 degenerate, 3 invalid_input (batchcol.STATUS names them)")
      .def_property_readonly("collide", [](py::object self) {
        const auto& r = self.cast<ResultsHolder&>().results;
        return view_bool_array(r.collide.data(), r.size(), self);
      })
      .def_property_readonly("distance", [](py::object self) {
        const auto& r = self.cast<ResultsHolder&>().results;
        return view_array(r.distance.data(), r.distance.size(), self);
      }, "signed distance, negative when overlapping (empty below level 'distance')")
      .def_property_readonly("witness_a", [](py::object self) {
        return view_xyz(self.cast<ResultsHolder&>().results.witness_a, self);
      }, "world-frame witness points on shape a: XYZ(x, y, z) of 1-D arrays (empty below level 'witness')")
      .def_property_readonly("witness_b", [](py::object self) {
        return view_xyz(self.cast<ResultsHolder&>().results.witness_b, self);
      })
      .def_property_readonly("normal", [](py::object self) {
        return view_xyz(self.cast<ResultsHolder&>().results.normal, self);
      }, "unit normal from shape a to shape b: XYZ(x, y, z) (empty below level 'witness')")
      .def_property_readonly("direction", [](py::object self) {
        return view_xyz(self.cast<ResultsHolder&>().results.direction, self);
      }, "final support direction; numpy.stack(direction, axis=1) is a warm_start for the next call")
      .def_property_readonly("iterations", [](py::object self) {
        const auto& r = self.cast<ResultsHolder&>().results;
        return view_array(r.iterations.data(), r.size(), self);
      });

  m.def(
      "collide",
      [](TableHolder& table, const py::handle& shape_a, const py::handle& shape_b, const py::handle& translation_a,
         const py::handle& quaternion_a, const py::handle& translation_b, const py::handle& quaternion_b,
         const std::string& level, const std::string& solver, const std::string& precision, double tolerance,
         double relative_tolerance, double margin, int max_iterations, int epa_max_iterations, bool closed_forms,
         int threads, const std::string& isa, const py::handle& warm_start, bool copy, const std::string& invalid,
         const py::handle& out) {
        if (invalid != "raise" && invalid != "status")
          throw ArgumentError("invalid must be 'raise' or 'status', got '" + invalid + "'");
        const QueryOptions o = options_from(level, solver, precision, tolerance, relative_tolerance, margin,
                                            max_iterations, epa_max_iterations, closed_forms, threads, isa);
        KeepAlive keep;
        const PairBatchView v = batch_input(shape_a, shape_b, translation_a, quaternion_a, translation_b,
                                            quaternion_b, warm_start, copy, keep);
        py::object result;
        if (out.is_none()) {
          result = py::cast(std::make_shared<ResultsHolder>());
        } else {
          // Reuse only when nothing is reallocated: arrays handed out earlier stay valid (and see the new values).
          result = py::reinterpret_borrow<py::object>(out);
          const auto& old = result.cast<ResultsHolder&>();
          if (old.busy > 0) throw std::runtime_error("out is being written by another running collide()");
          if (old.results.size() != v.size() || old.level != o.level)
            throw ArgumentError("out must be a Results of " + std::to_string(v.size()) + " pairs at level '" +
                                to_string(o.level) + "', got " + std::to_string(old.results.size()) + " pairs at '" +
                                to_string(old.level) + "'");
        }
        ResultsHolder& holder = result.cast<ResultsHolder&>();
        holder.level = o.level;
        {
          TableUse use(table);
          ++holder.busy;
          struct Done {
            int& busy;
            ~Done() { --busy; }
          } done{holder.busy};
          py::gil_scoped_release release;
          collide(*table.table, v, o, holder.results);
        }
        if (invalid == "raise") raise_invalid(*table.table, v, holder.results);
        return result;
      },
      "shapes"_a, "shape_a"_a, "shape_b"_a, "translation_a"_a, "quaternion_a"_a, "translation_b"_a,
      "quaternion_b"_a, py::kw_only(), "level"_a = "witness", "solver"_a = "automatic", "precision"_a = "double",
      "tolerance"_a = 1e-8, "relative_tolerance"_a = 0.0, "margin"_a = 0.0, "max_iterations"_a = 128,
      "epa_max_iterations"_a = 1000, "closed_forms"_a = true, "threads"_a = 0, "isa"_a = "automatic",
      "warm_start"_a = py::none(), "copy"_a = true, "invalid"_a = "raise", "out"_a = py::none());

  m.def(
      "_cpp_collide_seconds",
      [](const TableHolder& table, const py::handle& shape_a, const py::handle& shape_b,
         const py::handle& translation_a, const py::handle& quaternion_a, const py::handle& translation_b,
         const py::handle& quaternion_b, const std::string& level, int threads, int repeats, bool reuse_results, bool copy_to_batch) {
        const QueryOptions o = options_from(level, "automatic", "double", 1e-8, 0.0, 0.0, 128, 1000, true, threads,
                                            "automatic");
        KeepAlive keep;
        const PairBatchView v = batch_input(shape_a, shape_b, translation_a, quaternion_a, translation_b,
                                            quaternion_b, py::none(), true, keep);
        py::gil_scoped_release release;
        return cpp_collide_seconds(table, v, o, repeats, reuse_results, copy_to_batch);
      },
      "shapes"_a, "shape_a"_a, "shape_b"_a, "translation_a"_a, "quaternion_a"_a, "translation_b"_a,
      "quaternion_b"_a, "level"_a, "threads"_a, "repeats"_a, "reuse_results"_a, "copy_to_batch"_a);
}

}  // namespace batchcol::python
