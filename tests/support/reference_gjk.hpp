// Reference GJK for the tests: a plain scalar transcription of the algorithm the production wide kernel
// (kernels/simd/wide_gjk.inl) runs, one pair at a time, branch by branch. The wide kernel repeats every operation
// of this code in the same order, so each lane's result is bitwise this function's (tests/kernels/wide_gjk_test.cpp,
// tests/engine/executor_gjk_pairs_test.cpp). It is not linked into the library: an algorithm change is made in
// the wide kernel, and here to keep the check.
//   Gilbert, Johnson, Keerthi, "A fast procedure for computing the distance between complex objects", 1988.
//   Montaut, Le Lidec, Petrik, Sivic, Carpentier, "Collision detection accelerated: an optimization
//   perspective", RSS 2022 (Nesterov momentum delta_k = (k+1)/(k+3), normalised directions for shapes that are not
//   strictly convex, fallback to plain GJK when momentum stops helping).
// Minimising f(x) = |x|^2 / 2 over D: the gradient at x is x, a Frank-Wolfe step asks the support of D in
// direction -d, and the support point s gives the certified lower bound <s, d>/|d| on dist(0, D). We stop when
// |x| minus the best lower bound (an upper bound on the distance error) is below the tolerance; with d = x this is
// the duality gap (|x|^2 - <x, s>) / |x|.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"
#include "support/reference_simplex_projection.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// The gradient direction when x lies inside a triangle of the simplex. Rounding leaves x with an absolute error
/// of a few ulps of the vertices, so its direction is off by ~eps |w| / |x| (large when the shapes nearly touch);
/// the triangle's normal is off by ~eps |w|^2 / |n| instead. Return whichever is better conditioned, scaled to
/// |x| (both are the same direction in exact arithmetic).
template <class T> Vec3<T> face_direction(const Simplex<T>& S, const Vec3<T>& x) {
  const Vec3<T> n = cross3<T>(S.v[1].w - S.v[0].w, S.v[2].w - S.v[0].w);
  const T w = std::max({norm3(S.v[0].w), norm3(S.v[1].w), norm3(S.v[2].w)});
  const T xn = norm3(x), nn = norm3(n);
  if (!(nn > xn * w)) return x;
  return (dot3(n, x) < T(0) ? -n : n) * (xn / nn);
}

template <class T>
GjkResult<T> gjk(const MinkowskiDifference<T>& D, Vec3<T> initial_direction, const GjkParams<T>& params) {
  GjkResult<T> r;
  if (!(norm2(initial_direction) > T(0))) initial_direction = Vec3<T>::UnitX();
  Simplex<T>& S = r.simplex;
  S.v[0] = D.support(-initial_direction);
  S.lambda[0] = T(1);
  S.count = 1;
  Vec3<T> x = S.v[0].w;
  Vec3<T> d_prev = initial_direction;
  Vec3<T> last_s = x;
  assert(params.solver != Solver::automatic && "resolve_solver() first (set_gjk_parameters does)");
  bool momentum = params.solver != Solver::gjk;
  T lower_bound = -std::numeric_limits<T>::infinity();
  int stale = 0;  // consecutive iterations without real progress of the lower bound

  for (int k = 0; k < params.max_iterations; ++k) {
    r.iterations = k + 1;
    const T xx = norm2(x);
    const T xn = std::sqrt(xx);
    if (xn <= params.touch_tolerance) { r.status = GjkStatus::overlap; break; }
    if (params.boolean_only && xn <= params.core_margin) { r.status = GjkStatus::collision_proven; break; }

    Vec3<T> d = x;
    if (momentum && params.solver == Solver::nesterov) {
      const T delta = T(k + 1) / T(k + 3);
      const Vec3<T> y = delta * x + (T(1) - delta) * last_s;
      const T yn = norm3(y), dn = norm3(d_prev);
      if (params.normalize_momentum && yn > T(0) && dn > T(0)) d = delta * d_prev / dn + (T(1) - delta) * y / yn;
      else if (!params.normalize_momentum) d = delta * d_prev + (T(1) - delta) * y;
    } else if (momentum) {  // Polyak heavy ball: running average of the gradients with weight 1/(k+2)
      const T beta = T(1) / T(k + 2);
      d = (T(1) - beta) * x + beta * d_prev;
    }
    const T dn = norm3(d);
    if (!(dn > T(0))) d = x;  // momentum cancelled out: use the gradient
    const bool plain_step = (d == x);
    if (plain_step && S.count == 3) d = face_direction(S, x);

    const SupportPoint<T> s = D.support(-d);
    const T lb = dot3(s.w, d) / norm3(d);  // every y in D has <y, d/|d|> >= lb
    // Progress = closing at least a tenth of the certified gap |x| - lower_bound.
    stale = lb > lower_bound + T(0.1) * (xn - lower_bound) ? 0 : stale + 1;
    lower_bound = std::max(lower_bound, lb);
    r.direction = d;
    if (params.boolean_only && lb > params.core_margin) { r.status = GjkStatus::separated_proven; break; }

    const T tol = std::max(params.tolerance, params.relative_tolerance * xn);
    // Stop on the duality gap along x itself, (|x|^2 - <x, s>) / |x| = |x| - lb: it certifies the distance and
    // the normal -x/|x| (its support gap is <= tol). A bound from an earlier or a momentum direction certifies
    // |x| only and leaves the direction of x off by up to sqrt(2 |x| tol) / |x|, so it just switches to plain steps.
    if (plain_step && xn - lb <= tol) { r.status = GjkStatus::converged; break; }
    if (!plain_step && xn - lower_bound <= tol) {
      momentum = false;
      continue;
    }
    if (!plain_step && xx - dot3(x, s.w) <= tol * xn) {
      // The momentum support point would not move x: switch to plain GJK, whose gap certifies convergence.
      momentum = false;
      continue;
    }

    S.v[S.count++] = s;
    std::array<Vec3<T>, 4> pts;
    for (int i = 0; i < S.count; ++i) pts[i] = S.v[i].w;
    const SimplexProjection<T> proj = project_origin(pts.data(), S.count);
    Simplex<T> next;
    next.count = proj.count;
    for (int i = 0; i < proj.count; ++i) { next.v[i] = S.v[proj.index[i]]; next.lambda[i] = proj.lambda[i]; }
    const T next_xx = norm2(proj.x);
    if (proj.contains_origin) { S = next; x = proj.x; r.status = GjkStatus::overlap; break; }
    if (!(next_xx < xx)) {
      // No decrease although conv(W + s) contains x: we are at the resolution of the arithmetic.
      S.count -= 1;
      if (!plain_step) { momentum = false; continue; }
      r.status = xn <= T(2) * params.touch_tolerance ? GjkStatus::overlap : GjkStatus::stalled;
      break;
    }
    // Momentum whose step moves |x| by less than the tolerance is lagging behind the gradient (delta_k -> 1
    // makes the direction sluggish near a flat contact): finish with plain GJK steps, as Montaut et al. do.
    // Likewise when its support points stopped improving the lower bound (a simple adaptive restart, after
    // O'Donoghue and Candes, "Adaptive restart for accelerated gradient schemes", 2015).
    if (!plain_step && (xn - std::sqrt(next_xx) <= tol || stale >= kMaxStaleMomentumSteps)) momentum = false;
    S = next;
    x = proj.x;
    d_prev = d;
    last_s = s.w;
  }
  // The budget can run out right after x reached the origin.
  if (r.status == GjkStatus::max_iterations && norm3(x) <= params.touch_tolerance) r.status = GjkStatus::overlap;
  r.x = x;
  r.lower_bound = lower_bound;
  if (r.status == GjkStatus::overlap) r.x = Vec3<T>::Zero();
  return r;
}

}  // namespace batchcol::test_reference
