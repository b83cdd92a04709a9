#include "testkit/bench_pairs.hpp"
#include "testkit/portable_random.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>

namespace batchcol::testkit {
namespace {

using Random = PortableRandom;

const std::vector<BenchShapeKind>& primitive_kinds() {
  static const std::vector<BenchShapeKind> kinds = {
      {ShapeType::sphere, 0, "sphere"},      {ShapeType::capsule, 0, "capsule"}, {ShapeType::box, 0, "box"},
      {ShapeType::cylinder, 0, "cylinder"},  {ShapeType::cone, 0, "cone"},       {ShapeType::ellipsoid, 0, "ellipsoid"},
      {ShapeType::convex, 8, "convex8"}};
  return kinds;
}

BenchShapeKind parse_kind(const std::string& name, const std::string& spec) {
  if (name == "convex") return {ShapeType::convex, 8, "convex8"};
  if (name == "convex250") return {ShapeType::convex, 250, "convex250"};
  if (name == "convex940") return {ShapeType::convex, 940, "convex940"};
  for (const BenchShapeKind& kind : primitive_kinds()) {
    if (kind.name == name) return kind;
  }
  throw InputError("--case " + spec + ": unknown shape type '" + name +
                   "' (valid: sphere, capsule, box, cylinder, cone, ellipsoid, convex8, convex250, convex940, or "
                   "the case 'all')");
}

// Dimensions (radii, half extents, half lengths) in [1 cm, 20 cm], i.e. shapes of 2-40 cm.
double dimension(Random& rng) { return rng.uniform(0.01, 0.2); }

Shape random_shape(const BenchShapeKind& kind, Random& rng) {
  // Every draw is its own statement: the evaluation order of function arguments is unspecified.
  const double r = dimension(rng);
  const double h = dimension(rng);
  const double c = dimension(rng);
  switch (kind.type) {
    case ShapeType::sphere: return Shape::sphere(r);
    case ShapeType::capsule: return Shape::capsule(r, h);
    case ShapeType::box: return Shape::box(r, h, c);
    case ShapeType::cylinder: return Shape::cylinder(r, h);
    case ShapeType::cone: return Shape::cone(r, h);
    case ShapeType::ellipsoid: return Shape::ellipsoid(r, h, c);
    default: break;
  }
  // Hulls: points on an ellipsoid, all of them extreme, so the hull has kind.hull_vertices vertices.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < kind.hull_vertices; ++i) points.push_back(rng.unit_vector().cwiseProduct(Eigen::Vector3d(r, h, c)));
  return Shape::convex(points);
}

// A point inside the shape (the hull's vertex mean; the origin otherwise) from which b starts overlapping a.
Eigen::Vector3d inner_point(const Shape& s) { return s.hull ? s.hull->centroid : Eigen::Vector3d::Zero(); }

struct Candidate {
  std::uint32_t a = 0, b = 0;
  Pose pose_a, pose_b;
  Eigen::Vector3d start, direction;  // b's inner point sits at start + t * direction
  double target = 0, lo = 0, hi = 0, t = 0, reference = 0;
  bool done = false, failed = false;
};

void place(const ShapeTable& shapes, Candidate& c, double t) {
  c.t = t;
  c.pose_b.translation = c.start + t * c.direction - c.pose_b.rotation * inner_point(shapes[c.b]);
}

// The reference signed distance is a continuous function s(t) of the offset. It is convex in t (minus a concave
// depth while overlapping, a convex distance once separated), so from s(0) < target it crosses the target once.
// Newton steps use ds/dt = <normal, direction>, exact on flat patches; bisection keeps them inside the bracket.
void solve_offsets(const ShapeTable& shapes, std::vector<Candidate>& cands, const QueryOptions& ref) {
  constexpr int kMaxRounds = 80;
  for (int round = 0; round <= kMaxRounds; ++round) {
    std::vector<std::size_t> active;
    PairBatch batch;
    for (std::size_t i = 0; i < cands.size(); ++i) {
      if (cands[i].done || cands[i].failed) continue;
      active.push_back(i);
      batch.add(cands[i].a, cands[i].pose_a, cands[i].b, cands[i].pose_b);
    }
    if (active.empty()) return;
    PairResults r;
    collide(shapes, batch, ref, r);
    for (std::size_t k = 0; k < active.size(); ++k) {
      Candidate& c = cands[active[k]];
      const double s = r.distance[k];
      // The starting point (inner points together) may be a near-concentric overlap whose depth EPA cannot
      // certify to 1e-12 (a circle of minimising directions); only its sign matters there.
      const bool usable = r.status[k] == Status::converged || (round == 0 && s < c.target);
      if (!usable || !std::isfinite(s) || round == kMaxRounds) {
        c.failed = true;
        continue;
      }
      if (round == 0 && s >= c.target) {  // the inner points do not overlap deeply enough: draw another pair
        c.failed = true;
        continue;
      }
      // Accept within 0.1% of the target: the regime is a range, and the exact value is s itself.
      if (std::abs(s - c.target) <= 1e-3 * std::abs(c.target)) {
        c.done = true;
        c.reference = s;
        continue;
      }
      (s < c.target ? c.lo : c.hi) = c.t;
      const double slope = r.normal[k].dot(c.direction);
      double next = 0.5 * (c.lo + c.hi);
      if (round > 0 && slope > 1e-3) {
        const double newton = c.t + (c.target - s) / slope;
        if (newton > c.lo && newton < c.hi) next = newton;
      }
      place(shapes, c, next);
    }
  }
}

}  // namespace

std::vector<BenchCase> parse_bench_cases(const std::string& spec) {
  std::vector<BenchCase> cases;
  if (spec == "all") {
    const auto& kinds = primitive_kinds();
    for (std::size_t i = 0; i < kinds.size(); ++i) {
      for (std::size_t j = i; j < kinds.size(); ++j) cases.push_back({kinds[i], kinds[j]});
    }
    cases.push_back({parse_kind("convex250", spec), parse_kind("convex250", spec)});
    cases.push_back({parse_kind("convex940", spec), parse_kind("convex940", spec)});
    return cases;
  }
  const auto dash = spec.find('-');
  if (dash == std::string::npos || spec.find('-', dash + 1) != std::string::npos) {
    throw InputError("--case " + spec + ": expected TYPE-TYPE (e.g. sphere-box) or 'all'");
  }
  cases.push_back({parse_kind(spec.substr(0, dash), spec), parse_kind(spec.substr(dash + 1), spec)});
  return cases;
}

Regime parse_regime(const std::string& name) {
  if (name == "distant") return Regime::distant;
  if (name == "close") return Regime::close;
  if (name == "overlap") return Regime::overlap;
  throw InputError("--regime " + name + ": unknown regime (valid: distant, close, overlap)");
}

const char* to_string(Regime regime) {
  switch (regime) {
    case Regime::distant: return "distant";
    case Regime::close: return "close";
    case Regime::overlap: return "overlap";
  }
  return "?";
}

DistanceRange regime_range(Regime regime) {
  switch (regime) {
    case Regime::distant: return {0.1, 1.0};
    case Regime::close: return {1e-4, 1e-2};
    case Regime::overlap: return {-1e-2, -1e-4};
  }
  return {0, 0};
}

QueryOptions reference_options(int threads) {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.solver = Solver::gjk;
  o.precision = Precision::float64;
  o.tolerance = 1e-12;
  o.closed_forms = false;
  o.max_iterations = 1000;  // curved pairs at 1e-12 need more than the default 128
  o.threads = threads;
  return o;
}

BenchPairs make_bench_pairs(const BenchCase& bench_case, Regime regime, std::size_t count, std::uint64_t seed,
                            int threads) {
  Random rng(seed);
  BenchPairs out;
  // A pool per side: large hulls are few (qhull on 940 points per pair would dominate the set-up).
  const auto pool_size = [](const BenchShapeKind& k) { return k.hull_vertices > 100 ? 16u : 64u; };
  std::vector<std::uint32_t> pool_a, pool_b;
  for (unsigned i = 0; i < pool_size(bench_case.a); ++i) pool_a.push_back(out.shapes.add(random_shape(bench_case.a, rng)));
  for (unsigned i = 0; i < pool_size(bench_case.b); ++i) pool_b.push_back(out.shapes.add(random_shape(bench_case.b, rng)));

  const DistanceRange range = regime_range(regime);
  const QueryOptions ref = reference_options(threads);
  std::vector<Candidate> accepted;
  for (int attempt = 0; accepted.size() < count; ++attempt) {
    if (attempt == 20) throw InputError("bench: could not place " + bench_case.name() + " pairs in the " + to_string(regime) + " regime");
    const std::size_t missing = count - accepted.size();
    std::vector<Candidate> cands(missing + missing / 8 + 8);
    for (Candidate& c : cands) {
      c.a = pool_a[rng.index(pool_a.size())];
      c.b = pool_b[rng.index(pool_b.size())];
      for (int axis = 0; axis < 3; ++axis) c.pose_a.translation[axis] = rng.uniform(-1.0, 1.0);
      c.pose_a.rotation = rng.rotation();
      c.pose_b.rotation = rng.rotation();
      c.direction = rng.unit_vector();
      c.target = rng.uniform(range.lo, range.hi);
      c.start = c.pose_a.translation + c.pose_a.rotation * inner_point(out.shapes[c.a]);
      // Every point of a shape is within 2 * bounding_radius of its inner point, so s(hi) > target.
      c.hi = 2.0 * (out.shapes[c.a].bounding_radius() + out.shapes[c.b].bounding_radius()) + std::abs(c.target) + 0.01;
      place(out.shapes, c, 0.0);
    }
    solve_offsets(out.shapes, cands, ref);
    for (const Candidate& c : cands) {
      if (c.done && accepted.size() < count) accepted.push_back(c);
    }
  }
  out.pairs.reserve(count);
  for (const Candidate& c : accepted) {
    out.pairs.add(c.a, c.pose_a, c.b, c.pose_b);
    out.reference.push_back(c.reference);
  }
  return out;
}

}  // namespace batchcol::testkit
