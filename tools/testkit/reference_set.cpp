#include "testkit/reference_set.hpp"
#include "testkit/analytic_reference.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::testkit {
namespace {

bool strictly_convex(ShapeType t) { return t == ShapeType::sphere || t == ShapeType::ellipsoid; }

}  // namespace

ReferenceSet compute_references(const BenchPairs& p, int threads) {
  ReferenceSet set;
  const std::size_t n = p.pairs.size();
  PairResults numeric;
  collide(p.shapes, p.pairs, reference_options(threads), numeric);
  set.pairs.resize(n);
  std::size_t analytic = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Shape& a = p.shapes[p.pairs.shape_a[i]];
    const Shape& b = p.shapes[p.pairs.shape_b[i]];
    const auto closed = analytic_reference(a, p.pairs.pose_a(i), b, p.pairs.pose_b(i));
    if (closed) {
      set.pairs[i] = *closed;
      ++analytic;
      if (numeric.status[i] == Status::converged) {
        set.analytic_vs_numeric = std::max(set.analytic_vs_numeric, std::abs(closed->distance - numeric.distance[i]));
      }
      continue;
    }
    ReferencePair& r = set.pairs[i];
    r.distance = numeric.distance[i];
    r.witness_a = numeric.witness_a[i];
    r.witness_b = numeric.witness_b[i];
    r.normal = numeric.normal[i];
    r.certified = numeric.status[i] == Status::converged && std::isfinite(r.distance);
  }
  if (n > 0) {  // every pair of a bench case has the same two shape types
    const ShapeType a = p.shapes[p.pairs.shape_a[0]].type, b = p.shapes[p.pairs.shape_b[0]].type;
    set.unique_witnesses = strictly_convex(a) || strictly_convex(b) || has_closed_form(a, b);
  }
  set.kind = analytic == n ? "analytic" : analytic == 0 ? "gjk-1e-12" : "analytic+gjk-1e-12";
  return set;
}

}  // namespace batchcol::testkit
