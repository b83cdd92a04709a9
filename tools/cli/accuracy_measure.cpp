#include "cli/accuracy_measure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace batchcol::cli {
namespace {

// Radius of the point probe: the smallest sphere the factories accept is any positive one; 1e-9 m is added back to
// the probe's distance, exactly enough (the sum rounds at 1e-25 m).
constexpr double kProbeRadius = 1e-9;
// A timed run repeats collide() until it lasts this long, so that small batches are not timer noise.
constexpr double kMinRunSeconds = 0.01;

const double kInfinity = std::numeric_limits<double>::infinity();

ErrorStats stats_of(std::vector<double> v) {
  ErrorStats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto rank = [&](double q) { return v[std::size_t(std::ceil(q * double(v.size()))) - 1]; };
  s.median = rank(0.5);
  s.p99 = rank(0.99);
  s.max = v.back();
  return s;
}

double angle_between(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return std::atan2(u.cross(v).norm(), u.dot(v));  // accurate for tiny angles, unlike acos
}

QueryOptions probe_options(int threads) {
  QueryOptions o = reference_options(threads);
  o.closed_forms = true;  // the engine's own point-box/-sphere/-capsule forms are exact
  return o;
}

// Where witness points are not unique (a face or an edge may be closest), a returned pair is right when both points
// lie on their shapes' boundaries and are the reference distance apart: then it is one of the optimal pairs. The
// error is the largest of |signed distance of pa to A|, |signed distance of pb to B| and ||pb - pa| - |reference||,
// the first two measured by the tight reference against a point probe placed at the witness.
std::vector<double> surface_errors(const CaseData& data, const PairResults& r, const QueryOptions& probe) {
  const std::size_t n = r.size();
  PairBatch batch;
  batch.reserve(2 * n);
  const auto& pairs = data.pairs.pairs;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d pa = r.witness_a[i], pb = r.witness_b[i];
    const auto finite_or_origin = [](const Eigen::Vector3d& v) { return v.allFinite() ? v : Eigen::Vector3d::Zero(); };
    batch.add(pairs.shape_a[i], pairs.pose_a(i), data.probe, Pose::from_translation(finite_or_origin(pa)));
    batch.add(pairs.shape_b[i], pairs.pose_b(i), data.probe, Pose::from_translation(finite_or_origin(pb)));
  }
  PairResults on_surface;
  collide(data.probe_shapes, batch, probe, on_surface);
  std::vector<double> errors(n, kInfinity);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d pa = r.witness_a[i], pb = r.witness_b[i];
    if (!pa.allFinite() || !pb.allFinite()) continue;
    const double off_a = std::abs(on_surface.distance[2 * i] + kProbeRadius);
    const double off_b = std::abs(on_surface.distance[2 * i + 1] + kProbeRadius);
    const double gap = std::abs((pb - pa).norm() - std::abs(data.reference.pairs[i].distance));
    errors[i] = std::max({off_a, off_b, gap});
    if (!std::isfinite(errors[i])) errors[i] = kInfinity;
  }
  return errors;
}

template <class Run> double median_seconds_per_call(Run&& run, int runs, double first_seconds) {
  const int repeats = std::max(1, int(std::ceil(kMinRunSeconds / std::max(first_seconds, 1e-9))));
  std::vector<double> seconds;
  for (int k = 0; k < runs; ++k) {
    const auto start = std::chrono::steady_clock::now();
    for (int rep = 0; rep < repeats; ++rep) run();
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats);
  }
  std::sort(seconds.begin(), seconds.end());
  return seconds[seconds.size() / 2];
}

}  // namespace

QueryLevel query_level_for(Regime regime) {
  return regime == Regime::overlap ? QueryLevel::penetration : QueryLevel::witness;
}

CaseData prepare_case(const BenchCase& bench_case, Regime regime, std::size_t pairs, std::uint64_t seed, int threads) {
  CaseData d;
  d.bench_case = bench_case;
  d.regime = regime;
  d.pairs = make_bench_pairs(bench_case, regime, pairs, seed, threads);
  d.reference = compute_references(d.pairs, threads);
  const PairBatch& b = d.pairs.pairs;
  for (std::size_t i = 0; i < b.size(); ++i) {
    d.scale.push_back(d.pairs.shapes[b.shape_a[i]].bounding_radius() + d.pairs.shapes[b.shape_b[i]].bounding_radius() +
                      (b.translation_b[i] - b.translation_a[i]).norm());
  }
  d.probe_shapes = d.pairs.shapes;
  d.probe = d.probe_shapes.add(Shape::sphere(kProbeRadius));
  return d;
}

AccuracyRow measure(const CaseData& data, const SweepPoint& point, const MeasureSettings& settings) {
  QueryOptions options;
  options.level = query_level_for(data.regime);
  options.solver = point.solver;
  options.precision = point.precision;
  options.tolerance = point.tolerance;
  options.closed_forms = false;  // measure the solvers; the closed forms would answer sphere/capsule pairs exactly
  options.max_iterations = settings.max_iterations;
  options.threads = settings.threads;
  validate(options);

  const PairBatch& batch = data.pairs.pairs;
  PairResults results;
  const auto first_start = std::chrono::steady_clock::now();
  collide(data.pairs.shapes, batch, options, results);  // warm-up; results are the same bits on every run
  const double first = std::chrono::duration<double>(std::chrono::steady_clock::now() - first_start).count();
  PairResults scratch;
  const double seconds = median_seconds_per_call(
      [&] { collide(data.pairs.shapes, batch, options, scratch); }, settings.runs, first);

  AccuracyRow row;
  row.case_name = data.bench_case.name();
  row.regime = data.regime;
  row.point = point;
  row.level = options.level;
  row.pairs = batch.size();
  row.threads = settings.threads;
  row.reference = data.reference.kind;
  row.witness_measure = data.reference.unique_witnesses ? "points" : "surface";
  row.ns_per_pair = seconds * 1e9 / double(batch.size());
  row.pairs_per_second = seconds > 0 ? double(batch.size()) / seconds : 0.0;
  row.reference_check = data.reference.analytic_vs_numeric;

  const std::vector<double> surface =
      data.reference.unique_witnesses ? std::vector<double>() : surface_errors(data, results, probe_options(settings.threads));
  std::vector<double> distance, relative, witness, normal;
  double iterations = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    iterations += results.iterations[i];
    row.iterations_max = std::max(row.iterations_max, int(results.iterations[i]));
    row.not_converged += results.status[i] == Status::converged ? 0 : 1;
    const ReferencePair& ref = data.reference.pairs[i];
    if (!ref.certified) continue;
    ++row.scored;
    if (!std::isfinite(results.distance[i])) {
      ++row.non_finite;
      for (auto* v : {&distance, &relative, &witness, &normal}) v->push_back(kInfinity);
      continue;
    }
    const double error = std::abs(results.distance[i] - ref.distance);
    distance.push_back(error);
    relative.push_back(error / data.scale[i]);
    const double off_a = (results.witness_a[i] - ref.witness_a).norm();
    const double off_b = (results.witness_b[i] - ref.witness_b).norm();
    const double w = data.reference.unique_witnesses ? std::max(off_a, off_b) : surface[i];
    witness.push_back(std::isfinite(off_a) && std::isfinite(off_b) && std::isfinite(w) ? w : kInfinity);
    const double angle = angle_between(results.normal[i], ref.normal);
    normal.push_back(std::isfinite(angle) ? angle : kInfinity);
  }
  row.iterations_mean = results.size() > 0 ? iterations / double(results.size()) : 0.0;
  row.distance = stats_of(distance);
  row.witness = stats_of(witness);
  row.normal = stats_of(normal);
  row.distance_relative_max = stats_of(relative).max;
  return row;
}

}  // namespace batchcol::cli
