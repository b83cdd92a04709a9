#include "kernels/narrowphase.hpp"

#include "kernels/closed_forms.hpp"
#include "kernels/epa.hpp"
#include "kernels/gjk.hpp"
#include "kernels/point_depth.hpp"
#include "kernels/same_frame_depth.hpp"
#include "kernels/segment_depth.hpp"
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"

#include <type_traits>

namespace batchcol::kernels {
namespace {

/// GJK on one setup: the production wide kernel at width 1 (the scalar instruction set's build), so a pair that
/// comes through here gets the same algorithm, and the same bits, as a lane of the SIMD batches.
template <class T> GjkResult<T> run_gjk(const PairSetup<T>& s) {
  GjkResult<T> g;
  simd::gjk_lanes<T>(InstructionSet::scalar, &s, 1, &g, s.params.solver, true);
  return g;
}

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

}  // namespace

bool may_have_closed_form(ShapeType a, ShapeType b, const QueryOptions& opt) {
  if (a == ShapeType::halfspace || b == ShapeType::halfspace) return true;
  if (!opt.closed_forms) return false;
  const auto either = [&](ShapeType x, ShapeType y) { return (a == x && b == y) || (a == y && b == x); };
  if (is_point_or_segment(a) && is_point_or_segment(b)) return true;
  if (either(ShapeType::sphere, ShapeType::box)) return true;
  return either(ShapeType::box, ShapeType::box) && opt.level == QueryLevel::boolean && opt.margin == 0.0;
}

namespace {

/// Keeps only what the query level asked for (the rest is NaN) and sets `collide`.
template <class T> void finish(PairOutput<T>& o, const QueryOptions& opt, bool known_collide, bool collide) {
  o.collide = known_collide ? collide : (o.distance <= T(opt.margin));
  const Vec3<T> nan3 = Vec3<T>::Constant(quiet_nan<T>());
  if (opt.level == QueryLevel::boolean) o.distance = quiet_nan<T>();
  if (opt.level <= QueryLevel::distance) o.witness_a = o.witness_b = o.normal = nan3;
}

/// A GJK stall is accepted as `converged` only when its certificate |x| - lower bound is within kStallFloors
/// precision floors (or the tolerance): x and the lower bound are each known to about one floor (16 eps scale
/// covers the rounding of the support values, of x's projection and of the dot products), so 2 floors is what
/// the arithmetic can certify. Float stalls above it come from the simplex projection losing its sliver
/// simplices in single precision, not from the limit of the arithmetic: measured on 20k random float
/// curved-curved pairs at tolerance 1e-7, such stalls were accepted with errors up to 33 floors (2.9e-5 m on a
/// 0.6 m cylinder-ellipsoid pair 1e-6 m apart).
constexpr int kStallFloors = 2;

template <class T> bool stall_above_floor(const GjkCompletion<T>& c, const GjkResult<T>& g) {
  return g.x.norm() - g.lower_bound > std::max(c.tolerance, T(kStallFloors) * c.floor);
}

template <class T> ShapeCore<double> widen(const ShapeCore<T>& c) {
  ShapeCore<double> d;
  d.type = c.type;
  d.size = c.size.template cast<double>();
  d.radius = c.radius;
  d.hull = c.hull;
  for (int i = 0; i < 3; ++i) d.triangle[i] = c.triangle[i].template cast<double>();
  d.halfspace_normal = c.halfspace_normal.template cast<double>();
  d.halfspace_offset = c.halfspace_offset;
  return d;
}

/// A float pair whose GJK stalled above 2 float floors is solved again by plain GJK in double, on the same float
/// cores and relative pose, starting from the stalled point. Measured on those 20k pairs (3
/// solvers): 0.2% of the pairs, +0.2% iterations, every one converged within 1.5 floors; reporting them
/// `degenerate` instead would fail 0.2% of float queries, and restarting plain GJK in float left a quarter of them
/// stalled. A stall of the double run must pass the same 2-float-floor test, else the pair is `degenerate`.
PairOutput<float> redo_in_double(const PairSetup<float>& s, const GjkResult<float>& g, const QueryOptions& opt);

}  // namespace

template <class T>
void setup_pair_into(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                     const Eigen::Vector3d& warm_direction,
                     const QueryOptions& opt, PairSetup<T>& s) {
  s.A = make_core<T>(a);
  s.B = make_core<T>(b);
  const ShapeCore<T>& A = s.A;
  const ShapeCore<T>& B = s.B;
  s.X.R = b_in_a.R.cast<T>();
  s.X.t = b_in_a.t.cast<T>();
  s.done = false;
  // The separating-axis test is exact for boolean queries on plain boxes with a zero margin.
  if (opt.closed_forms && a.type == ShapeType::box && b.type == ShapeType::box && opt.level == QueryLevel::boolean &&
      opt.margin == 0.0 && A.radius == T(0) && B.radius == T(0)) {
    s.out = PairOutput<T>{};
    finish(s.out, opt, true, boxes_intersect(A.size, B.size, s.X));
    s.done = true;
    return;
  }
  if (closed_form(A, B, s.X, opt, s.out)) {
    finish(s.out, opt, false, false);
    s.done = true;
    return;
  }

  // GJK on the cores; the swept radii are added afterwards.
  set_gjk_parameters(s, a.bounding_radius, b.bounding_radius, norm3(b_in_a.t), Vec3<T>(warm_direction.cast<T>()),
                     opt);
}

template <class T>
PairSetup<T> setup_pair(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                        const Eigen::Vector3d& warm_direction, const QueryOptions& opt) {
  PairSetup<T> s;
  setup_pair_into(a, b, b_in_a, warm_direction, opt, s);
  return s;
}

template <class T>
bool complete_from_gjk(const GjkCompletion<T>& c, const GjkResult<T>& g, const QueryOptions& opt,
                       PairOutput<T>& out) {
  out = PairOutput<T>{};
  out.iterations = g.iterations;
  out.direction = g.direction;

  switch (g.status) {
    case GjkStatus::separated_proven: finish(out, opt, true, false); return true;
    case GjkStatus::collision_proven: finish(out, opt, true, true); return true;
    case GjkStatus::overlap:
      if (opt.level == QueryLevel::penetration) return false;  // EPA needs the cores
      finish(out, opt, true, true);
      return true;
    default: break;
  }
  // Separated or touching cores: x = witness_a - witness_b of the cores.
  const T xn = g.x.norm();
  const Vec3<T> n = -g.x / xn;  // xn > 0 here: x == 0 ends GJK with GjkStatus::overlap
  out.status = Status::converged;
  if (g.status == GjkStatus::max_iterations) out.status = Status::max_iterations;
  if (g.status == GjkStatus::stalled && stall_above_floor(c, g)) {
    if constexpr (std::is_same_v<T, float>) return false;  // redone in double on the cores
    // Double has no wider type to fall back on. Its stall is accepted when the certified error is within what the
    // arithmetic can certify. Two limits: (1) the lower bound <s, d>/|d| inherits the direction error of d,
    // ~ eps scale / |x|, times the lateral extent of D (~ scale); (2) a Frank-Wolfe step decreases |x|^2 by
    // ~ gap^2 / |x - s|^2, which rounds to nothing once the distance gap is below ~ sqrt(eps) |x - s|. The
    // distance itself is usually far more accurate than this certificate (measured against closed forms by the
    // hard-case tests: 1.2e-10 m at tolerance 1e-12 on curved shapes 1e-9 m apart). Limit (1) is capped at the
    // larger of |x| and limit (2): it must not grow without bound as |x| -> 0.
    const T scale = c.scale, floor = c.floor;
    const T sqrt_limit = T(4) * std::sqrt(machine_epsilon<T>()) * scale;
    const T certifiable = std::max(std::min(T(4) * floor * (T(1) + scale / xn), std::max(xn, sqrt_limit)), sqrt_limit);
    if (xn - g.lower_bound > std::max(c.tolerance, certifiable)) out.status = Status::degenerate;
  }
  out.distance = xn - c.radii;
  out.normal = n;
  out.witness_a = g.witness_a() + c.radius_a * n;
  out.witness_b = g.witness_b() - c.radius_b * n;
  // collide: when the gap certified the distance (or the budget ran out), it is decided conservatively, false
  // only when a separating plane beyond the margin is certified (a loose tolerance must not turn a shallow
  // overlap into a separation). After an accepted stall the certificate is at the arithmetic's limit and the
  // distance estimate decides.
  if (g.status == GjkStatus::stalled) finish(out, opt, false, false);
  else finish(out, opt, true, !(g.lower_bound > c.core_margin));
  // A degenerate stall is returned filled but unfinished: complete_pair() may answer it exactly (issue #16).
  return out.status != Status::degenerate;
}

namespace {

/// point_depth_in_core(), or for a point on or a hair outside the core (GJK's overlap within its touch tolerance:
/// 16 float ulps of the size in float), a negative depth: minus that distance (EPA would run on an origin on the
/// boundary of D: it ended degenerate on sphere centres 1e-12 m outside a cylinder in float).
template <class T> bool point_depth_in_core_or_on_it(const ShapeCore<T>& core, const Vec3<T>& p, PointDepth<T>& d) {
  if (point_depth_in_core(core, p, d)) return true;
  PointDistance<T> outside;
  if (!point_distance_to_core(core, p, outside)) return false;
  d.depth = -outside.distance;  // witness_a - witness_b = closest - p = depth * normal still holds
  d.normal = outside.normal;
  return true;
}

/// A sphere whose centre is a hair outside a cylinder or cone core: GJK stalls with an exact |x| but a certificate
/// spoilt by x's direction (kernels/point_depth.hpp), measured up to 3.6e-5 m above the tolerance for centres 1e-12
/// to 1e-10 m from the core, under every solver; the point's distance to the core, in closed form, replaces it.
template <class T>
bool point_core_distance(const PairSetup<T>& s, const GjkResult<T>& g, const QueryOptions& opt, PairOutput<T>& out) {
  PointDistance<T> d;
  Vec3<T> normal, on_a, on_b;  // unit from A to B; the cores' closest points (A's frame)
  if (s.B.type == ShapeType::sphere) {
    if (!point_distance_to_core(s.A, s.X.t, d)) return false;
    normal = d.normal;
    on_a = d.closest;
    on_b = s.X.t;
  } else if (s.A.type == ShapeType::sphere) {
    if (!point_distance_to_core(s.B, mul_transposed(s.X.R, Vec3<T>(-s.X.t)), d)) return false;
    normal = -mul(s.X.R, d.normal);
    on_a = Vec3<T>::Zero();
    on_b = s.X.apply(d.closest);
  } else {
    return false;
  }
  out = PairOutput<T>{};
  out.status = Status::converged;
  out.iterations = g.iterations;
  out.direction = g.direction;
  out.distance = d.distance - s.radii;
  out.normal = normal;
  out.witness_a = on_a + s.A.radius * normal;
  out.witness_b = on_b - s.B.radius * normal;
  finish(out, opt, false, false);
  return true;
}

/// The same for a segment core (a capsule) and a cylinder or cone core.
template <class T> bool segment_core_depth(const PairSetup<T>& s, EpaResult<T>& e) {
  SegmentDepth<T> d;
  if (s.B.type == ShapeType::capsule) {
    const Vec3<T> end(T(0), T(0), s.B.size.y());  // B's segment, in A's frame
    if (!segment_depth_in_core(s.A, s.X.apply(Vec3<T>(-end)), s.X.apply(end), d)) return false;
    e.normal = d.normal;
    e.witness_a = d.on_a;
  } else if (s.A.type == ShapeType::capsule) {
    const Vec3<T> end(T(0), T(0), s.A.size.y());  // A's segment, in B's frame
    const auto to_b = [&](const Vec3<T>& x) { return mul_transposed(s.X.R, Vec3<T>(x - s.X.t)); };
    if (!segment_depth_in_core(s.B, to_b(Vec3<T>(-end)), to_b(end), d)) return false;
    e.normal = -mul(s.X.R, d.normal);
    e.witness_a = s.X.apply(Vec3<T>(d.on_a - d.depth * d.normal));
  } else {
    return false;
  }
  e.depth = d.depth;
  e.witness_b = e.witness_a - d.depth * e.normal;
  e.status = EpaStatus::converged;
  e.iterations = 0;
  return true;
}

/// EPA's answer, in closed form, when one core is a point (a sphere) or a segment (a capsule) overlapping the
/// other, a cylinder or cone core (kernels/point_depth.hpp, kernels/segment_depth.hpp), or for two ellipsoids in
/// the same frame (kernels/same_frame_depth.hpp). False for every other pair.
template <class T> bool point_core_depth(const PairSetup<T>& s, EpaResult<T>& e) {
  PointDepth<T> d;
  if (s.B.type == ShapeType::sphere) {
    const Vec3<T> p = s.X.t;  // B's point core, in A's frame
    if (!point_depth_in_core_or_on_it(s.A, p, d)) return false;
    e.normal = d.normal;  // from A to B: B leaves A through A's boundary
    e.witness_b = p;
    e.witness_a = p + d.depth * d.normal;
  } else if (s.A.type == ShapeType::sphere) {
    const Vec3<T> p = mul_transposed(s.X.R, Vec3<T>(-s.X.t));  // A's point core, in B's frame
    if (!point_depth_in_core_or_on_it(s.B, p, d)) return false;
    e.normal = -mul(s.X.R, d.normal);  // A leaves B through B's boundary: from A to B is against B's outward normal
    e.witness_a = Vec3<T>::Zero();
    e.witness_b = s.X.apply(Vec3<T>(p + d.depth * d.normal));
  } else {
    return segment_core_depth(s, e) || same_frame_ellipsoids_depth(s.A, s.B, s.X, s.params.tolerance, e);
  }
  e.depth = d.depth;  // witness_a - witness_b = depth * normal, as EPA's
  e.status = EpaStatus::converged;
  e.iterations = 0;
  return true;
}

}  // namespace

template <class T>
PairOutput<T> complete_pair(const PairSetup<T>& s, const GjkResult<T>& g, const QueryOptions& opt) {
  const GjkCompletion<T> c{s.A.radius, s.B.radius, s.radii, s.scale, s.floor, s.params.tolerance,
                           s.params.core_margin};
  PairOutput<T> out;
  if (complete_from_gjk(c, g, opt, out)) return out;
  if (g.status == GjkStatus::stalled && point_core_distance(s, g, opt, out)) return out;
  if (g.status != GjkStatus::overlap) {
    if constexpr (std::is_same_v<T, float>) return redo_in_double(s, g, opt);
    else return out;  // a double stall above what the arithmetic certifies: degenerate (complete_from_gjk)
  }
  // Overlapping cores at QueryLevel::penetration: depth and witnesses by EPA, or in closed form for a sphere
  // centred inside, or a capsule overlapping, a cylinder or cone (where EPA converges too slowly:
  // kernels/point_depth.hpp, kernels/segment_depth.hpp).
  EpaResult<T> e;
  if (!point_core_depth(s, e)) e = epa(s.difference(), g.simplex, s.params.tolerance, s.scale, opt.epa_max_iterations);
  out = PairOutput<T>{};
  out.iterations = g.iterations + e.iterations;
  out.direction = g.direction;
  out.status = e.status == EpaStatus::converged || e.status == EpaStatus::flat ? Status::converged
               : e.status == EpaStatus::max_iterations                          ? Status::max_iterations
                                                                                 : Status::degenerate;
  out.normal = e.normal;
  out.distance = -e.depth - s.radii;
  out.witness_a = e.witness_a + s.A.radius * e.normal;
  out.witness_b = e.witness_b - s.B.radius * e.normal;
  finish(out, opt, true, true);
  return out;
}

namespace {

PairOutput<float> redo_in_double(const PairSetup<float>& s, const GjkResult<float>& g, const QueryOptions& opt) {
  // The pair as double sees it: the float cores and relative pose, with double's own floor, touch tolerance and
  // requested tolerance (a certificate at the float floor would leave the normal off by up to
  // sqrt(2 tolerance / |x|): measured 3.6e-3 rad on sphere-cylinder overlaps).
  PairSetup<double> d;
  d.A = widen(s.A);
  d.B = widen(s.B);
  d.X.R = s.X.R.cast<double>();
  d.X.t = s.X.t.cast<double>();
  d.radii = s.radii;
  d.scale = s.scale;
  d.floor = tolerance_floor(double(s.scale));
  GjkParams<double>& p = d.params;
  p.solver = Solver::gjk;
  p.tolerance = std::max(opt.tolerance, d.floor);
  p.relative_tolerance = opt.relative_tolerance;
  p.max_iterations = s.params.max_iterations;
  p.boolean_only = s.params.boolean_only;
  p.core_margin = s.params.core_margin;
  p.touch_tolerance = d.floor;
  d.initial_direction = g.x.cast<double>();
  const GjkResult<double> gd = run_gjk(d);
  PairOutput<double> o = complete_pair(d, gd, opt);
  // Its stall is judged by what float promises (2 float floors), not by double's own limits.
  const double float_limit = std::max(double(s.params.tolerance), kStallFloors * double(s.floor));
  if (gd.status == GjkStatus::stalled)
    o.status = gd.x.norm() - gd.lower_bound > float_limit ? Status::degenerate : Status::converged;
  PairOutput<float> out;
  out.status = o.status;
  out.collide = o.collide;
  out.distance = float(o.distance);
  out.witness_a = o.witness_a.cast<float>();
  out.witness_b = o.witness_b.cast<float>();
  out.normal = o.normal.cast<float>();
  out.direction = o.direction.cast<float>();
  out.iterations = g.iterations + o.iterations;
  return out;
}

}  // namespace

template <class T>
PairOutput<T> solve_pair(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                         const Eigen::Vector3d& warm_direction, const QueryOptions& opt) {
  const PairSetup<T> s = setup_pair<T>(a, b, b_in_a, warm_direction, opt);
  if (s.done) return s.out;
  return complete_pair(s, run_gjk(s), opt);
}

template PairOutput<double> solve_pair<double>(const ShapeView&, const ShapeView&, const RelativePose&,
                                               const Eigen::Vector3d&, const QueryOptions&);
template PairOutput<float> solve_pair<float>(const ShapeView&, const ShapeView&, const RelativePose&,
                                             const Eigen::Vector3d&, const QueryOptions&);
template void setup_pair_into<double>(const ShapeView&, const ShapeView&, const RelativePose&,
    const Eigen::Vector3d&, const QueryOptions&, PairSetup<double>&);
template void setup_pair_into<float>(const ShapeView&, const ShapeView&, const RelativePose&,
    const Eigen::Vector3d&, const QueryOptions&, PairSetup<float>&);
template PairSetup<double> setup_pair<double>(const ShapeView&, const ShapeView&, const RelativePose&,
                                              const Eigen::Vector3d&, const QueryOptions&);
template PairSetup<float> setup_pair<float>(const ShapeView&, const ShapeView&, const RelativePose&,
                                            const Eigen::Vector3d&, const QueryOptions&);
template bool complete_from_gjk<double>(const GjkCompletion<double>&, const GjkResult<double>&, const QueryOptions&,
                                         PairOutput<double>&);
template bool complete_from_gjk<float>(const GjkCompletion<float>&, const GjkResult<float>&, const QueryOptions&,
                                        PairOutput<float>&);
template PairOutput<double> complete_pair<double>(const PairSetup<double>&, const GjkResult<double>&,
                                                  const QueryOptions&);
template PairOutput<float> complete_pair<float>(const PairSetup<float>&, const GjkResult<float>&,
                                                const QueryOptions&);

}  // namespace batchcol::kernels
