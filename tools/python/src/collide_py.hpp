// Shared by collide_py.cpp and scene_py.cpp: the results object and the batch arguments.
#pragma once

#include "arrays.hpp"

#include "batchcol/batch.hpp"

namespace batchcol::python {

/// The Python Results: owns the engine's result buffers; its arrays are views of them.
struct ResultsHolder {
  PairResults results;
  QueryLevel level = QueryLevel::witness;
  int busy = 0;  // a collide(out=...) is writing it with the GIL released
};

/// Views (or copies, see arrays.hpp) of collide()'s pair arguments, named as in the Python signature.
PairBatchView batch_input(const py::handle& shape_a, const py::handle& shape_b, const py::handle& translation_a,
                          const py::handle& quaternion_a, const py::handle& translation_b,
                          const py::handle& quaternion_b, const py::handle& warm_start, bool copy, KeepAlive& keep);

/// Raises ArgumentError naming the first pair whose status is invalid_input and why (invalid="raise").
void raise_invalid(const ShapeTable& shapes, const PairBatchView& b, const PairResults& r);

/// An owning copy of a view's pairs (without warm starts).
PairBatch batch_copy(const PairBatchView& v);

/// QueryOptions from the keyword arguments of collide() (names parsed and values validated by the engine).
QueryOptions options_from(const std::string& level, const std::string& solver, const std::string& precision,
                          double tolerance, double relative_tolerance, double margin, int max_iterations,
                          int epa_max_iterations, bool closed_forms, int threads, const std::string& isa);

}  // namespace batchcol::python
