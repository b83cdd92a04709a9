// One measurement of `batchcol accuracy`: a case and regime (seeded pairs and their reference) run through
// collide() with one solver, precision and tolerance; throughput (median of timed runs) and the error statistics
// against the reference.
#pragma once

#include "testkit/reference_set.hpp"
#include "testkit/bench_pairs.hpp"

#include <batchcol/batch.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace batchcol::cli {

using testkit::BenchCase;
using testkit::BenchPairs;
using testkit::ReferencePair;
using testkit::ReferenceSet;
using testkit::Regime;
using testkit::compute_references;
using testkit::make_bench_pairs;
using testkit::parse_bench_cases;
using testkit::parse_regime;
using testkit::reference_options;

/// The pairs of one case and regime with everything the error measures need, built once and shared by the sweep.
struct CaseData {
  BenchCase bench_case;
  Regime regime = Regime::close;
  BenchPairs pairs;
  ReferenceSet reference;
  /// Size the relative distance error is measured in: the engine's precision scale (QueryOptions::tolerance),
  /// bounding radius of a + bounding radius of b + distance between their origins.
  std::vector<double> scale;
  ShapeTable probe_shapes;    // the case's shapes plus a point probe (surface witness measure)
  std::uint32_t probe = 0;
};

CaseData prepare_case(const BenchCase& bench_case, Regime regime, std::size_t pairs, std::uint64_t seed, int threads);

struct SweepPoint {
  Solver solver = Solver::gjk;
  Precision precision = Precision::float64;
  double tolerance = 1e-8;
};

struct MeasureSettings {
  int threads = 1;
  int runs = 3;  // timed runs; the median is reported
  int max_iterations = 1000;
};

/// Median, 99th percentile (nearest rank) and maximum; infinity when a result was not finite.
struct ErrorStats {
  double median = 0, p99 = 0, max = 0;
};

struct AccuracyRow {
  std::string case_name;
  Regime regime = Regime::close;
  SweepPoint point;
  QueryLevel level = QueryLevel::witness;
  std::size_t pairs = 0;
  int threads = 0;
  std::string reference;        // ReferenceSet::kind
  std::string witness_measure;  // "points" (distance to the reference witnesses) or "surface" (see accuracy_measure.cpp)
  double pairs_per_second = 0, ns_per_pair = 0;
  ErrorStats distance, witness, normal;
  double distance_relative_max = 0;  // max |distance error| / CaseData::scale
  double iterations_mean = 0;
  int iterations_max = 0;
  std::size_t scored = 0;         // pairs with a certified reference (the statistics are over these)
  std::size_t not_converged = 0;  // status max_iterations or degenerate
  std::size_t non_finite = 0;     // NaN or infinite distance
  double reference_check = 0;     // ReferenceSet::analytic_vs_numeric
};

AccuracyRow measure(const CaseData& data, const SweepPoint& point, const MeasureSettings& settings);

/// witness level for separated regimes, penetration for overlap (EPA gives the depth, its witnesses and normal).
QueryLevel query_level_for(Regime regime);

}  // namespace batchcol::cli
