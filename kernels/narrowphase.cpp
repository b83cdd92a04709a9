#include "kernels/narrowphase.hpp"

#include "kernels/closed_forms.hpp"
#include "kernels/epa.hpp"
#include "kernels/gjk.hpp"

namespace batchcol::kernels {
namespace {

bool is_point_or_segment(ShapeType t) { return t == ShapeType::sphere || t == ShapeType::capsule; }

template <class T> Transform<T> inverse(const Transform<T>& X) {
  Transform<T> inv;
  inv.R = X.R.transpose();
  inv.t = -(inv.R * X.t);
  return inv;
}

/// Maps the output of a kernel run with A and B exchanged back to the original roles (A's frame).
template <class T> PairOutput<T> swap_roles(PairOutput<T> o, const Transform<T>& b_in_a) {
  const Vec3<T> wa = o.witness_a;
  o.witness_a = b_in_a.apply(o.witness_b);
  o.witness_b = b_in_a.apply(wa);
  o.normal = -(b_in_a.R * o.normal);
  return o;
}

/// Closed forms for this pair, if one applies. Returns false when GJK must run.
template <class T>
bool closed_form(const ShapeCore<T>& A, const ShapeCore<T>& B, const Transform<T>& X, const QueryOptions& opt,
                 PairOutput<T>& out) {
  const ShapeType ta = A.type, tb = B.type;
  if (ta == ShapeType::halfspace && tb == ShapeType::halfspace) { out = halfspace_halfspace(A, B, X); return true; }
  if (ta == ShapeType::halfspace) { out = halfspace_shape(A, B, X); return true; }
  if (tb == ShapeType::halfspace) { out = swap_roles(halfspace_shape(B, A, inverse(X)), X); return true; }
  if (!opt.closed_forms) return false;
  if (is_point_or_segment(ta) && is_point_or_segment(tb)) { out = segment_cores(A, B, X); return true; }
  if (ta == ShapeType::sphere && tb == ShapeType::box) { out = sphere_box(A, B, X, false); return true; }
  if (ta == ShapeType::box && tb == ShapeType::sphere) { out = sphere_box(B, A, X, true); return true; }
  return false;
}

/// Keeps only what the query level asked for (the rest is NaN) and sets `collide`.
template <class T> void finish(PairOutput<T>& o, const QueryOptions& opt, bool known_collide, bool collide) {
  o.collide = known_collide ? collide : (o.distance <= T(opt.margin));
  const Vec3<T> nan3 = Vec3<T>::Constant(quiet_nan<T>());
  if (opt.level == QueryLevel::boolean) o.distance = quiet_nan<T>();
  if (opt.level <= QueryLevel::distance) o.witness_a = o.witness_b = o.normal = nan3;
}

}  // namespace

template <class T>
PairOutput<T> solve_pair(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                         const Eigen::Vector3d& warm_direction, const QueryOptions& opt) {
  const ShapeCore<T> A = make_core<T>(a), B = make_core<T>(b);
  Transform<T> X;
  X.R = b_in_a.R.cast<T>();
  X.t = b_in_a.t.cast<T>();
  PairOutput<T> out;
  // The separating-axis test is exact for boolean queries on plain boxes with a zero margin.
  if (opt.closed_forms && a.type == ShapeType::box && b.type == ShapeType::box && opt.level == QueryLevel::boolean &&
      opt.margin == 0.0 && A.radius == T(0) && B.radius == T(0)) {
    finish(out, opt, true, boxes_intersect(A.size, B.size, X));
    return out;
  }
  if (closed_form(A, B, X, opt, out)) {
    finish(out, opt, false, false);
    return out;
  }

  // GJK on the cores; the swept radii are added afterwards.
  const T radii = A.radius + B.radius;
  const T scale = T(a.bounding_radius() + b.bounding_radius() + b_in_a.t.norm());
  const T floor = tolerance_floor(scale);
  GjkParams<T> params;
  params.solver = opt.solver;
  params.tolerance = std::max(T(opt.tolerance), floor);
  params.relative_tolerance = T(opt.relative_tolerance);
  params.max_iterations = opt.max_iterations;
  params.boolean_only = opt.level == QueryLevel::boolean;
  params.core_margin = T(opt.margin) + radii;
  params.normalize_momentum = !(A.strictly_convex() && B.strictly_convex());
  params.touch_tolerance = floor;  // 16 ulps of the problem size
  const MinkowskiDifference<T> D{&A, &B, X, {}, {}};
  const Vec3<T> warm = warm_direction.cast<T>();
  const bool use_warm = warm.allFinite() && warm.squaredNorm() > T(0);
  const GjkResult<T> g = gjk(D, use_warm ? warm : D.center(), params);
  out.iterations = g.iterations;
  out.direction = g.direction;

  switch (g.status) {
    case GjkStatus::separated_proven: finish(out, opt, true, false); return out;
    case GjkStatus::collision_proven: finish(out, opt, true, true); return out;
    case GjkStatus::overlap: {
      if (opt.level < QueryLevel::penetration) { finish(out, opt, true, true); return out; }
      const EpaResult<T> e = epa(D, g.simplex, params.tolerance, scale, opt.epa_max_iterations);
      out.iterations += e.iterations;
      out.status = e.status == EpaStatus::converged || e.status == EpaStatus::flat ? Status::converged
                   : e.status == EpaStatus::max_iterations                          ? Status::max_iterations
                                                                                     : Status::degenerate;
      out.normal = e.normal;
      out.distance = -e.depth - radii;
      out.witness_a = e.witness_a + A.radius * e.normal;
      out.witness_b = e.witness_b - B.radius * e.normal;
      finish(out, opt, true, true);
      return out;
    }
    default: break;
  }
  // Separated or touching cores: x = witness_a - witness_b of the cores.
  const T xn = g.x.norm();
  const Vec3<T> n = -g.x / xn;  // xn > 0 here: x == 0 ends GJK with GjkStatus::overlap
  out.status = Status::converged;
  if (g.status == GjkStatus::max_iterations) out.status = Status::max_iterations;
  // A stall is accepted when the certified error is within what the arithmetic can certify. Two limits:
  // (1) the lower bound <s, d>/|d| inherits the direction error of d, ~ eps scale / |x|, times the lateral extent
  // of D (~ scale); (2) a Frank-Wolfe step decreases |x|^2 by ~ gap^2 / |x - s|^2, which rounds to nothing once
  // the distance gap is below ~ sqrt(eps) |x - s|. The distance itself is usually far more accurate than this
  // certificate (the tests measure it against closed forms).
  // Limit (1) is capped at the larger of |x| and limit (2): it must not grow without bound as |x| -> 0.
  const T sqrt_limit = T(4) * std::sqrt(machine_epsilon<T>()) * scale;
  const T certifiable = std::max(std::min(T(4) * floor * (T(1) + scale / xn), std::max(xn, sqrt_limit)), sqrt_limit);
  if (g.status == GjkStatus::stalled && xn - g.lower_bound > std::max(params.tolerance, certifiable))
    out.status = Status::degenerate;
  out.distance = xn - radii;
  out.normal = n;
  out.witness_a = g.witness_a() + A.radius * n;
  out.witness_b = g.witness_b() - B.radius * n;
  // collide: when the gap certified the distance (or the budget ran out), it is decided conservatively, false
  // only when a separating plane beyond the margin is certified (a loose tolerance must not turn a shallow
  // overlap into a separation). After an accepted stall the certificate is at the arithmetic's limit and the
  // distance estimate decides.
  if (g.status == GjkStatus::stalled) finish(out, opt, false, false);
  else finish(out, opt, true, !(g.lower_bound > params.core_margin));
  return out;
}

template PairOutput<double> solve_pair<double>(const Shape&, const Shape&, const RelativePose&,
                                               const Eigen::Vector3d&, const QueryOptions&);
template PairOutput<float> solve_pair<float>(const Shape&, const Shape&, const RelativePose&,
                                             const Eigen::Vector3d&, const QueryOptions&);

}  // namespace batchcol::kernels
