// batchcol.differentiate() on NumPy arrays and the Derivatives object whose arrays are views of the engine's buffers.
#include "arrays.hpp"
#include "collide_py.hpp"
#include "module.hpp"

#include "batchcol/derivatives.hpp"

#include <pybind11/stl.h>

#include <memory>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

/// The Python Derivatives: owns the engine's derivative buffers; its arrays are views of them.
struct DerivativesHolder {
  DerivativeResults d;
};

/// A (n, rows, columns) view of an engine array whose entry (r, c) of pair i is data[(columns r + c) n + i]
/// (Vec6Array: rows 1, returned as (n, 6); Mat36Array: (n, 3, 6)). Strided, no copy.
py::array view_soa(const LineAlignedDoubles& data, std::size_t n, int rows, int columns, const py::handle& owner) {
  const auto s = static_cast<py::ssize_t>(sizeof(double));
  const auto N = static_cast<py::ssize_t>(n);
  const double* p = data.empty() ? nullptr : data.data();
  if (data.empty()) n = 0;  // the Jacobians of a gradients-only call: (0, 3, 6)
  if (rows == 1)
    return py::array(py::dtype::of<double>(), {static_cast<py::ssize_t>(n), py::ssize_t{columns}}, {s, N * s}, p,
                     owner);
  return py::array(py::dtype::of<double>(), {static_cast<py::ssize_t>(n), py::ssize_t{rows}, py::ssize_t{columns}},
                   {s, columns * N * s, N * s}, p, owner);
}

}  // namespace

void register_derivatives(py::module_& m) {
  auto cls = py::class_<DerivativesHolder, std::shared_ptr<DerivativesHolder>>(
      m, "Derivatives",
      "Per-pair derivatives with respect to the shapes' twists (world frame, linear then angular; see the README), "
      "in input order. Every array is a view of the engine's buffers (no copy) and keeps this object alive.");
  cls.def("__len__", [](const DerivativesHolder& h) { return h.d.size(); })
      .def_property_readonly("status", [](py::object self) {
        const auto& d = self.cast<DerivativesHolder&>().d;
        static_assert(sizeof(DerivativeStatus) == 1, "statuses are bytes");
        return view_array(reinterpret_cast<const std::uint8_t*>(d.status.data()), d.size(), self);
      }, "uint8 codes (batchcol.DERIVATIVE_STATUS names them): 0 smooth, 1 zero_curvature, 2 nonsmooth, 3 singular, "
         "4 partial_samples, 5 no_witness");
  const auto vector_field = [&](const char* name, Vec6Array DerivativeResults::*field, const char* doc) {
    cls.def_property_readonly(name, [field](py::object self) {
      const auto& d = self.cast<DerivativesHolder&>().d;
      return view_soa((d.*field).data, d.size(), 1, 6, self);
    }, doc);
  };
  vector_field("distance_gradient_a", &DerivativeResults::distance_gradient_a,
               "(N, 6) d(signed distance) / d(twist of a), a strided view");
  vector_field("distance_gradient_b", &DerivativeResults::distance_gradient_b,
               "(N, 6) d(signed distance) / d(twist of b)");
  const std::pair<const char*, Mat36Array DerivativeResults::*> matrices[] = {
      {"witness_a_wrt_a", &DerivativeResults::witness_a_wrt_a}, {"witness_a_wrt_b", &DerivativeResults::witness_a_wrt_b},
      {"witness_b_wrt_a", &DerivativeResults::witness_b_wrt_a}, {"witness_b_wrt_b", &DerivativeResults::witness_b_wrt_b},
      {"normal_wrt_a", &DerivativeResults::normal_wrt_a},       {"normal_wrt_b", &DerivativeResults::normal_wrt_b}};
  for (const auto& [name, field] : matrices)
    cls.def_property_readonly(name, [field = field](py::object self) {
      const auto& d = self.cast<DerivativesHolder&>().d;
      return view_soa((d.*field).data, d.size(), 3, 6, self);
    }, "(N, 3, 6) Jacobian, a strided view; (0, 3, 6) when jacobians=False");
  cls.def_property_readonly("smoothed_distance", [](py::object self) {
        const auto& d = self.cast<DerivativesHolder&>().d;
        return view_array(d.smoothed_distance.data(), d.smoothed_distance.size(), self);
      }, "smoothed0 only (empty otherwise): the sample means")
      .def_property_readonly("smoothed_witness_a", [](py::object self) {
        return view_xyz(self.cast<DerivativesHolder&>().d.smoothed_witness_a, self);
      })
      .def_property_readonly("smoothed_witness_b", [](py::object self) {
        return view_xyz(self.cast<DerivativesHolder&>().d.smoothed_witness_b, self);
      })
      .def_property_readonly("smoothed_normal", [](py::object self) {
        return view_xyz(self.cast<DerivativesHolder&>().d.smoothed_normal, self);
      });

  m.def(
      "differentiate",
      [](TableHolder& table, const py::handle& shape_a, const py::handle& shape_b, const py::handle& translation_a,
         const py::handle& quaternion_a, const py::handle& translation_b, const py::handle& quaternion_b,
         const std::string& method, int samples, double noise, const std::string& noise_scale, std::uint64_t seed,
         bool jacobians, const std::string& level, const std::string& solver, const std::string& precision,
         double tolerance, double relative_tolerance, double margin, int max_iterations, int epa_max_iterations,
         bool closed_forms, int threads, const std::string& isa, const std::string& invalid) {
        if (invalid != "raise" && invalid != "status")
          throw ArgumentError("invalid must be 'raise' or 'status', got '" + invalid + "'");
        const QueryOptions o = options_from(level, solver, precision, tolerance, relative_tolerance, margin,
                                            max_iterations, epa_max_iterations, closed_forms, threads, isa);
        DerivativeOptions d;
        d.method = parse_derivative_method(method);
        d.samples = samples;
        d.noise = noise;
        d.noise_scale = parse_noise_scale(noise_scale);
        d.seed = seed;
        d.jacobians = jacobians;
        validate(d);
        KeepAlive keep;
        const PairBatchView v = batch_input(shape_a, shape_b, translation_a, quaternion_a, translation_b,
                                            quaternion_b, py::none(), true, keep);
        auto results = std::make_shared<ResultsHolder>();
        auto derivatives = std::make_shared<DerivativesHolder>();
        results->level = o.level;
        {
          TableUse use(table);
          py::gil_scoped_release release;
          // differentiate() takes an owning PairBatch (smoothed0 builds perturbed copies of it): one copy.
          const PairBatch batch = batch_copy(v);
          differentiate(*table.table, batch, o, d, results->results, derivatives->d);
        }
        if (invalid == "raise") raise_invalid(*table.table, v, results->results);
        return py::make_tuple(py::cast(results), py::cast(derivatives));
      },
      "shapes"_a, "shape_a"_a, "shape_b"_a, "translation_a"_a, "quaternion_a"_a, "translation_b"_a,
      "quaternion_b"_a, py::kw_only(), "method"_a = "analytic", "samples"_a = 16, "noise"_a = 1e-2,
      "noise_scale"_a = "relative", "seed"_a = 0, "jacobians"_a = true, "level"_a = "witness",
      "solver"_a = "automatic", "precision"_a = "double", "tolerance"_a = 1e-8, "relative_tolerance"_a = 0.0,
      "margin"_a = 0.0, "max_iterations"_a = 128, "epa_max_iterations"_a = 1000, "closed_forms"_a = true,
      "threads"_a = 0, "isa"_a = "automatic", "invalid"_a = "raise",
      "Runs the query and the derivatives of every pair (C++ differentiate()); returns (Results, Derivatives). "
      "level must be 'witness' or 'penetration'. Bad options raise ValueError naming them.");
}

}  // namespace batchcol::python
