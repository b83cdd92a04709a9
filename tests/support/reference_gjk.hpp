// Reference GJK for the tests: a plain scalar transcription of the algorithm the production wide kernel
// (kernels/simd/wide_gjk.inl) runs, one pair at a time, branch by branch. The wide kernel repeats every operation
// of this code in the same order, so each lane's result is bitwise this function's (tests/kernels/wide_gjk_test.cpp,
// tests/engine/executor_gjk_pairs_test.cpp). It is not linked into the library: an algorithm change is made in
// the wide kernel, and here to keep the check.
//   Gilbert, Johnson, Keerthi, "A fast procedure for computing the distance between complex objects", 1988.
//   Montaut, Le Lidec, Petrik, Sivic, Carpentier, "Collision detection accelerated: an optimization
//   perspective", RSS 2022 (Nesterov momentum delta_k = (k+1)/(k+3), normalised directions for shapes that are not
//   strictly convex, fallback to plain GJK when momentum stops helping).
// Distance / witness queries on curved cores (ellipsoid, cylinder, cone) switch to Newton search directions near the
// optimum: Newton on the optimality condition of the direction, with the support functions' Hessians
// (wide_gjk.inl's newton_direction()); the simplex, bounds and termination stay GJK's.
// Minimising f(x) = |x|^2 / 2 over D: the gradient at x is x, a Frank-Wolfe step asks the support of D in
// direction -d, and the support point s gives the certified lower bound <s, d>/|d| on dist(0, D). We stop when
// |x| minus the best lower bound (an upper bound on the distance error) is below the tolerance; with d = x this is
// the duality gap (|x|^2 - <x, s>) / |x|.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"
#include "support/reference_box_ellipsoid.hpp"
#include "support/reference_box_round.hpp"
#include "support/reference_point_hull.hpp"
#include "support/reference_rim_rim.hpp"
#include "support/reference_round_ellipsoid.hpp"
#include "support/reference_simplex_projection.hpp"
#include "support/reference_start_gate.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <type_traits>

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

// The wide kernel's V3 arithmetic, in its association order (with kernels/math.hpp's dot3 and cross3).
template <class T> Vec3<T> wscale(T s, const Vec3<T>& a) { return Vec3<T>(s * a.x(), s * a.y(), s * a.z()); }
template <class T> Vec3<T> wdivide(const Vec3<T>& a, T s) { return Vec3<T>(a.x() / s, a.y() / s, a.z() / s); }
template <class T> Vec3<T> wsub(const Vec3<T>& a, const Vec3<T>& b) {
  return Vec3<T>(a.x() - b.x(), a.y() - b.y(), a.z() - b.z());
}
template <class T> Vec3<T> wadd(const Vec3<T>& a, const Vec3<T>& b) {
  return Vec3<T>(a.x() + b.x(), a.y() + b.y(), a.z() + b.z());
}

/// Whether a core's support function has a curved part (wide_gjk.inl's curved()).
inline bool curved_core(ShapeType t) {
  return t == ShapeType::ellipsoid || t == ShapeType::cylinder || t == ShapeType::cone;
}

/// Hessian xx, yy, zz, xy, xz, yz of a cylinder's or cone's support function at the unit direction u (its frame):
/// the formulas and operations of wide_gjk.inl's support_hessian().
template <class T> std::array<T, 6> support_hessian(const ShapeCore<T>& core, const Vec3<T>& u) {
  std::array<T, 6> h{};
  const T s0 = core.size.x(), s1 = core.size.y();
  const T rho2 = u.x() * u.x() + u.y() * u.y();
  if (!(rho2 > T(0))) return h;
  if (core.type == ShapeType::cone && s1 * u.z() >= (-s1) * u.z() + s0 * std::sqrt(rho2)) return h;  // apex
  const T k = s0 / (rho2 * std::sqrt(rho2));
  h[0] = (k * u.y()) * u.y();
  h[1] = (k * u.x()) * u.x();
  h[3] = -((k * u.x()) * u.y());
  return h;
}

/// An ellipsoid's support Hessian in A's frame from its support point: (M - g g^T) / <g, u>, M = R diag(r^2) R^T
/// (wide_gjk.inl's ellipsoid_hessian(), which says why).
template <class T>
std::array<T, 6> ellipsoid_hessian(const std::array<T, 6>& M, const Vec3<T>& g, const Vec3<T>& u) {
  const T m = dot3(g, u);
  if (!(m > T(0))) return {};
  const T im = T(1) / m;
  return {(M[0] - g.x() * g.x()) * im, (M[1] - g.y() * g.y()) * im, (M[2] - g.z() * g.z()) * im,
          (M[3] - g.x() * g.y()) * im, (M[4] - g.x() * g.z()) * im, (M[5] - g.y() * g.z()) * im};
}

/// R diag(r^2) R^T of an ellipsoid with radii r (wide_gjk.inl's ellipsoid_metric()).
template <class T> std::array<T, 6> ellipsoid_metric(const ShapeCore<T>& core, const Mat3<T>& R) {
  const T q[3] = {core.size.x() * core.size.x(), core.size.y() * core.size.y(), core.size.z() * core.size.z()};
  T P[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) P[i][k] = R(i, k) * q[k];
  const auto e = [&](int i, int j) { return (P[i][0] * R(j, 0) + P[i][1] * R(j, 1)) + P[i][2] * R(j, 2); };
  return {e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(0, 2), e(1, 2)};
}

/// A cylinder's or cone's rim Hessian in A's frame, B's pose R (wide_gjk.inl's rim_hessian()).
template <class T> std::array<T, 6> rim_hessian(const ShapeCore<T>& core, const Mat3<T>& R, const Vec3<T>& n) {
  const Vec3<T> axis(R(0, 2), R(1, 2), R(2, 2));
  const Vec3<T> c = cross3(axis, n);
  const T rho2 = dot3(c, c);
  if (!(rho2 > T(0))) return {};
  const T s0 = core.size.x(), s1 = core.size.y(), rho = std::sqrt(rho2);
  if (core.type == ShapeType::cone) {
    const T uz = dot3(axis, n);
    if (s1 * uz >= (-s1) * uz + s0 * rho) return {};  // apex
  }
  const T k = s0 / (rho2 * rho);
  const Vec3<T> kc(k * c.x(), k * c.y(), k * c.z());
  return {kc.x() * c.x(), kc.y() * c.y(), kc.z() * c.z(), kc.x() * c.y(), kc.x() * c.z(), kc.y() * c.z()};
}

/// H = H_A(-n) + R H_B(R^T n) R^T as xx, yy, zz, xy, xz, yz from the support point s in direction -n:
/// wide_gjk.inl's pair_hessian().
template <class T>
std::array<T, 6> pair_hessian(const MinkowskiDifference<T>& D, const Vec3<T>& n, const SupportPoint<T>& s) {
  std::array<T, 6> h{};
  const bool ca = curved_core(D.A->type), cb = curved_core(D.B->type);
  if (ca) {
    if (D.A->type == ShapeType::ellipsoid) {
      const T s0 = D.A->size.x(), s1 = D.A->size.y(), s2 = D.A->size.z();
      h = ellipsoid_hessian<T>({s0 * s0, s1 * s1, s2 * s2, T(0), T(0), T(0)}, s.a, Vec3<T>(-n));
    } else {
      h = support_hessian(*D.A, Vec3<T>(-n));
    }
  }
  if (cb) {
    const auto& R = D.b_in_a.R;
    const std::array<T, 6> hb = D.B->type == ShapeType::ellipsoid
                                    ? ellipsoid_hessian(ellipsoid_metric(*D.B, R), wsub(s.b, D.b_in_a.t), n)
                                    : rim_hessian(*D.B, R, n);
    if (ca) for (int i = 0; i < 6; ++i) h[i] = h[i] + hb[i];
    else h = hb;
  }
  return h;
}

/// (H + lb I)^-1 r by cofactors: wide_gjk.inl's solve().
template <class T> Vec3<T> newton_solve(const std::array<T, 6>& h, T lb, const Vec3<T>& r) {
  const T a = h[0] + lb, b = h[1] + lb, c = h[2] + lb, p = h[3], q = h[4], t = h[5];
  const T c00 = b * c - t * t, c01 = q * t - p * c, c02 = p * t - b * q;
  const T c11 = a * c - q * q, c12 = p * q - a * t, c22 = a * b - p * p;
  const T det = (a * c00 + p * c01) + q * c02;
  const T inv = T(1) / det;
  return Vec3<T>(((c00 * r.x() + c01 * r.y()) + c02 * r.z()) * inv, ((c01 * r.x() + c11 * r.y()) + c12 * r.z()) * inv,
                 ((c02 * r.x() + c12 * r.y()) + c22 * r.z()) * inv);
}

/// Newton's direction after the support point w of D in direction -n (unit n, lb = <w, n>, r = w - lb n):
/// wide_gjk.inl's newton_direction(), where the derivation is: n + delta with (H + lb I) delta = r; step2 =
/// |delta|^2.
template <class T>
Vec3<T> newton_direction(const MinkowskiDifference<T>& D, const Vec3<T>& n, const SupportPoint<T>& s,
                         const Vec3<T>& r, T lb, T& step2) {
  const Vec3<T> delta = newton_solve(pair_hessian(D, n, s), lb, r);
  step2 = norm2(delta);
  return Vec3<T>(n.x() + delta.x(), n.y() + delta.y(), n.z() + delta.z());
}

/// Newton's direction for a polytope against a curved core (flat_newton_side()): wide_gjk.inl's
/// feature_direction(), where the derivation is. S: the simplex after this iteration's projection; s: the support
/// point in direction -n.
template <class T>
Vec3<T> feature_direction(const MinkowskiDifference<T>& D, const Simplex<T>& S, const Vec3<T>& n,
                          const SupportPoint<T>& s, T& step2) {
  const bool fa = flat_newton_side(D.A->type, D.B->type) == 1;
  const auto flat = [&](int m) { return fa ? S.v[m].a : S.v[m].b; };
  const Vec3<T> p0 = flat(0);
  const Vec3<T> y = fa ? wsub(p0, s.b) : wsub(s.a, p0);
  const T lb = dot3(y, n);
  const Vec3<T> r = wsub(y, wscale(lb, n));
  const std::array<T, 6> h = pair_hessian(D, n, s);
  const bool has1 = S.count > 1 && !(flat(1) == p0);
  const bool has2 = S.count > 2 && !(flat(2) == p0) && !(flat(2) == flat(1));
  const Vec3<T> e1 = S.count > 1 ? wsub(flat(1), p0) : Vec3<T>::Zero();
  const Vec3<T> e2 = S.count > 2 ? wsub(flat(2), p0) : Vec3<T>::Zero();
  const Vec3<T> m = cross3(e1, e2);
  const T mm = dot3(m, m);
  const bool is_face = has1 && has2 && mm > T(1e-12) * (dot3(e1, e1) * dot3(e2, e2));
  const bool is_edge = !is_face && (has1 || has2);
  Vec3<T> delta;
  if (is_face) {
    const T sq = std::sqrt(mm);
    const Vec3<T> f = wdivide(m, dot3(m, n) < T(0) ? -sq : sq);
    delta = wsub(f, n);
  } else if (is_edge) {
    const Vec3<T> e = has1 ? e1 : e2;
    const Vec3<T> c = cross3(n, e);
    const T cn = std::sqrt(dot3(c, c));
    const Vec3<T> u = wdivide(c, cn);
    const Vec3<T> v = wdivide(wsub(e, wscale(dot3(e, n), n)), cn);
    const T alpha = -dot3(n, e) / cn;
    const Vec3<T> hu((h[0] * u.x() + h[3] * u.y()) + h[4] * u.z(), (h[3] * u.x() + h[1] * u.y()) + h[5] * u.z(),
                     (h[4] * u.x() + h[5] * u.y()) + h[2] * u.z());
    const T beta = (dot3(u, y) - alpha * dot3(v, hu)) / (dot3(u, hu) + lb);
    delta = wadd(wscale(alpha, v), wscale(beta, u));
  } else {
    delta = newton_solve(h, lb, r);
  }
  step2 = dot3(delta, delta);
  return wadd(n, delta);
}

/// The closed-form start point of a cylinder / capsule pair (wide_gjk.inl's side_start(), where
/// the reasoning is), with its operations: true and the point of D with its points of A and B where the axis
/// segments' closest points are a side contact.
template <class T> bool side_start(const MinkowskiDifference<T>& D, SupportPoint<T>& p) {
  const auto clamp = [](T z, T h) { return z > h ? h : (z < -h ? -h : z); };
  const T ha = D.A->size.y(), hb = D.B->size.y();
  const bool cyl_a = D.A->type == ShapeType::cylinder, cyl_b = D.B->type == ShapeType::cylinder;
  const T ra = cyl_a ? D.A->size.x() : T(0), rb = cyl_b ? D.B->size.x() : T(0);
  const Vec3<T> c = D.b_in_a.t;
  const Vec3<T> b(D.b_in_a.R(0, 2), D.b_in_a.R(1, 2), D.b_in_a.R(2, 2));
  const T beta = b.z(), cb = dot3(c, b), bb = dot3(b, b);
  const T denom = bb - beta * beta;
  const T zb1 = denom > T(0) ? (beta * c.z() - cb) / denom : T(0);
  const bool out_b1 = zb1 > hb || zb1 < -hb;
  const T zb1c = clamp(zb1, hb);
  const T za = c.z() + zb1c * beta;
  const bool out_a = za > ha || za < -ha;
  const T zac = clamp(za, ha);
  const T zb2 = (zac * beta - cb) / bb;
  const bool out_b2 = zb2 > hb || zb2 < -hb;
  const T zb = out_a ? clamp(zb2, hb) : zb1c;
  if (cyl_a && out_a) return false;
  if (cyl_b && (out_a ? out_b2 : out_b1)) return false;
  const Vec3<T> qa(T(0), T(0), zac), qb = wadd(c, wscale(zb, b));
  const Vec3<T> v = wsub(qa, qb);
  const T vn = std::sqrt(dot3(v, v));
  if (!(vn > ra + rb)) return false;
  const Vec3<T> u = wdivide(v, vn);
  p.a = wsub(qa, wscale(ra, u));
  p.b = wadd(qb, wscale(rb, u));
  p.w = wsub(p.a, p.b);
  return true;
}

/// wide_gjk.inl's rim_lateral() (the reasoning is there), with its operations: a rim of X (radius r, height zr, X's
/// frame) against Y's lateral surface (centre c, unit axis b, radius ry, half-height hy, cone or cylinder); false
/// where the foot py is not on the surface or px not outside it.
template <class T>
bool rim_lateral(T r, T zr, const Vec3<T>& c, const Vec3<T>& b, T ry, T hy, bool cone, Vec3<T>& px, Vec3<T>& py) {
  T C, S;
  lateral_start(r, zr, c, b, ry, hy, cone, C, S);
  const T kr = T(2) * hy;
  for (int it = 0; it < kRimNewtonSteps; ++it) {
    const Vec3<T> v(r * C - c.x(), r * S - c.y(), zr - c.z());
    const Vec3<T> v1(-(r * S), r * C, T(0)), v2(-(r * C), -(r * S), T(0));
    const T vb = dot3(v, b), v1b = dot3(v1, b), v2b = dot3(v2, b);
    const T g = dot3(v, v1) - vb * v1b;
    const T h = (dot3(v1, v1) + dot3(v, v2)) - (v1b * v1b + vb * v2b);
    T dt;
    if (cone) {
      const T ir = T(1) / std::sqrt(dot3(v, v) - vb * vb);
      const T r1 = g * ir, r2 = (h - r1 * r1) * ir;
      const T f1 = kr * r1 + ry * v1b, f2 = kr * r2 + ry * v2b;
      const T den = f2 + (f1 * r1) * ir;
      dt = den > T(0) ? -f1 / den : T(0);
    } else {
      dt = h > T(0) ? -g / h : T(0);
    }
    const T C1 = C - dt * S, S1 = S + dt * C;
    const T inv = T(1) / std::sqrt(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  px = Vec3<T>(r * C, r * S, zr);
  const Vec3<T> v = wsub(px, c);
  const T vb = dot3(v, b);
  const Vec3<T> e = wsub(v, wscale(vb, b));
  const T rho = std::sqrt(dot3(e, e));
  if (cone) {
    const T sg = (rho * ry - kr * (vb - hy)) / (ry * ry + kr * kr);
    py = wadd(wadd(c, wscale(hy - kr * sg, b)), wscale((sg * ry) / rho, e));
    return sg >= T(0) && sg <= T(1) && kr * rho + ry * (vb - hy) > T(0) && rho > T(0);
  }
  py = wadd(wadd(c, wscale(vb, b)), wscale(ry / rho, e));
  return vb <= hy && vb >= -hy && rho > ry;
}

/// wide_gjk.inl's rim_candidate() for one pair: the closest valid candidate point of D, only where its direction
/// separates the cores (false: none). Cylinder / cone pairs: rim_lateral() both ways, round_round() both ways, then
/// side_slant() (cylinder-cone) or slant_slant() (cone-cone);
/// a capsule against a cylinder / cone: round_segment() in the round core's frame (reference_rim_rim.hpp).
template <class T> bool rim_candidate(const MinkowskiDifference<T>& D, SupportPoint<T>& p) {
  const ShapeType ta = D.A->type, tb = D.B->type;
  const T a0 = D.A->size.x(), a1 = D.A->size.y(), b0 = D.B->size.x(), b1 = D.B->size.y();
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  bool has = false;
  T best = T(0);
  const auto keep = [&](bool ok, const Vec3<T>& qa, const Vec3<T>& qb) {
    const Vec3<T> w = wsub(qa, qb);
    const T n2 = dot3(w, w);
    if (ok && (!has || n2 < best)) {
      p.a = qa;
      p.b = qb;
      best = n2;
      has = true;
    }
  };
  const Vec3<T> c = t, b(R(0, 2), R(1, 2), R(2, 2));
  const Vec3<T> ca(-((R(0, 0) * t.x() + R(1, 0) * t.y()) + R(2, 0) * t.z()),
                   -((R(0, 1) * t.x() + R(1, 1) * t.y()) + R(2, 1) * t.z()),
                   -((R(0, 2) * t.x() + R(1, 2) * t.y()) + R(2, 2) * t.z()));
  const Vec3<T> a(R(2, 0), R(2, 1), R(2, 2));
  const auto back = [&](const Vec3<T>& q) {
    return Vec3<T>(((R(0, 0) * q.x() + R(0, 1) * q.y()) + R(0, 2) * q.z()) + t.x(),
                   ((R(1, 0) * q.x() + R(1, 1) * q.y()) + R(1, 2) * q.z()) + t.y(),
                   ((R(2, 0) * q.x() + R(2, 1) * q.y()) + R(2, 2) * q.z()) + t.z());
  };
  if (ta == ShapeType::capsule || tb == ShapeType::capsule) {
    if (tb == ShapeType::capsule) {
      round_segment(a0, a1, ta == ShapeType::cone, c, b, b1,
                    [&](bool ok, const Vec3<T>& px, T z) { keep(ok, px, back(Vec3<T>(T(0), T(0), z))); });
    } else {
      round_segment(b0, b1, tb == ShapeType::cone, ca, a, a1,
                    [&](bool ok, const Vec3<T>& px, T z) { keep(ok, Vec3<T>(T(0), T(0), z), back(px)); });
    }
  } else {
    for (int sg = ta == ShapeType::cone ? -1 : 1; sg >= -1; sg -= 2) {
      Vec3<T> qa, qb;
      const bool ok = rim_lateral(a0, T(sg) * a1, c, b, b0, b1, tb == ShapeType::cone, qa, qb);
      keep(ok, qa, qb);
    }
    for (int sg = tb == ShapeType::cone ? -1 : 1; sg >= -1; sg -= 2) {
      Vec3<T> qb, qa;
      const bool ok = rim_lateral(b0, T(sg) * b1, ca, a, a0, a1, ta == ShapeType::cone, qb, qa);
      keep(ok, back(qa), back(qb));
    }
    round_round(a0, a1, ta == ShapeType::cone, c, b, b0, b1, tb == ShapeType::cone, true,
                [&](bool ok, const Vec3<T>& px, const Vec3<T>& py) { keep(ok, px, py); });
    round_round(b0, b1, tb == ShapeType::cone, ca, a, a0, a1, ta == ShapeType::cone, false,
                [&](bool ok, const Vec3<T>& px, const Vec3<T>& py) { keep(ok, back(py), back(px)); });
    if (ta == ShapeType::cone && tb == ShapeType::cylinder) {
      Vec3<T> px, py;
      const bool ok = side_slant(b0, b1, a0, a1, c, b, px, py);
      keep(ok, px, py);
    } else if (ta == ShapeType::cylinder && tb == ShapeType::cone) {
      Vec3<T> px, py;
      const bool ok = side_slant(a0, a1, b0, b1, ca, a, px, py);
      keep(ok, back(py), back(px));
    } else if (ta == ShapeType::cone && tb == ShapeType::cone) {
      Vec3<T> px, py;
      const bool ok = slant_slant(a0, a1, c, b, b0, b1, px, py);
      keep(ok, px, py);
    }
  }
  if (!has) return false;
  const T Rr[9] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
  if (!round_apart(ta, tb, Rr, t, a0, a1, b0, b1, p.a, p.b)) return false;
  p.w = wsub(p.a, p.b);
  return true;
}

template <class T>
GjkResult<T> gjk(const MinkowskiDifference<T>& D, Vec3<T> initial_direction, const GjkParams<T>& params) {
  GjkResult<T> r;
  if (!(norm2(initial_direction) > T(0))) initial_direction = Vec3<T>::UnitX();
  Simplex<T>& S = r.simplex;
  S.v[0] = D.support(-initial_direction);
  [[maybe_unused]] const SupportPoint<T> first = S.v[0];  // the start gate's points (side_start() may replace S.v[0])
  S.lambda[0] = T(1);
  S.count = 1;
  Vec3<T> x = S.v[0].w;
  Vec3<T> d_prev = initial_direction;
  Vec3<T> last_s = x;
  assert(params.solver != Solver::automatic && "resolve_solver() first (set_gjk_parameters does)");
  bool momentum = params.solver != Solver::gjk;
  // Sphere-hull pairs in double, distance and witness queries: the centre's nearest point on the most separating
  // face replaces the first support point wherever it is finite, and the first step is a plain one
  // (wide_gjk_point_hull.inl, reference_point_hull.hpp).
  if (std::is_same_v<T, double> && !params.boolean_only && point_hull_pair(D.A->type, D.B->type)) {
    SupportPoint<T> p;
    if (point_hull_candidate(D, p)) {
      S.v[0] = p;
      x = p.w;
      last_s = x;
      momentum = false;
    }
  }
  // A closed-form start point replaces the first support point where it is closer; the first step is then a plain
  // one (wide_gjk.inl's start()).
  const auto take_start = [&](bool found, const SupportPoint<T>& p) {
    if (found && norm2(p.w) < norm2(x)) {
      S.v[0] = p;
      x = p.w;
      last_s = x;
      momentum = false;
    }
  };
  // Cylinder / capsule pairs: the closed-form side contact (wide_gjk.inl's side_start()).
  if (!params.boolean_only && side_start_pair(D.A->type, D.B->type)) {
    SupportPoint<T> p;
    const bool found = side_start(D, p);
    take_start(found, p);
  }
  // Pairs whose cores certainly overlap (their first support point's points inside the other core) compute no
  // closed-form candidate: none could separate the cores (wide_gjk.inl's start(), reference_start_gate.hpp).
  if constexpr (std::is_same_v<T, double>) {
    if (!params.boolean_only && start_candidate_pair(D.A->type, D.B->type) && !cores_overlap(D, first)) {
      // Each type pair's candidate (double): computed where the pair type has one, kept by take_start().
      const auto candidate = [&](bool pair, auto&& find) {
        if (!pair) return;
        SupportPoint<T> p;
        const bool found = find(D, p);
        take_start(found, p);
      };
      // Rim-lateral pairs: the closest rim-lateral point of D.
      candidate(rim_start_pair(D.A->type, D.B->type), [](const auto& d, auto& p) { return rim_candidate(d, p); });
      // Box-, capsule- and sphere-ellipsoid pairs: the closest face / edge / vertex point of D.
      candidate(box_ellipsoid_pair(D.A->type, D.B->type),
                [](const auto& d, auto& p) { return box_ellipsoid_candidate(d, p); });
      // Box-cylinder / box-cone pairs: the closest face / edge / vertex / apex point of D.
      candidate(box_round_pair(D.A->type, D.B->type), [](const auto& d, auto& p) { return box_round_candidate(d, p); });
      // Cylinder- / cone-ellipsoid pairs: the closest cap / rim / apex / side / slant Newton point of D.
      candidate(round_ellipsoid_pair(D.A->type, D.B->type),
                [](const auto& d, auto& p) { return round_ellipsoid_candidate(d, p); });
    }
  }
  T lower_bound = -std::numeric_limits<T>::infinity();
  int stale = 0;  // consecutive iterations without real progress of the lower bound
  // Newton directions (witness / distance queries of newton_pair_type()s) until one fails to progress.
  bool newton = !params.boolean_only && newton_pair_type(D.A->type, D.B->type);
  bool newton_next = false;
  Vec3<T> newton_dir = Vec3<T>::Zero();
  T newton_step2 = T(0);  // |delta|^2 of the step that chose newton_dir
  const bool flat_pair = flat_newton_side(D.A->type, D.B->type) != 0;  // feature_direction()
  T newton_gap = T(0);    // flat pairs: the certified gap when the last Newton choice was made

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
    const bool newton_step = newton_next;
    if (newton_step) {  // Newton's direction replaces plain GJK's and momentum's, and ends momentum
      d = newton_dir;
      momentum = false;
      r.newton_steps += 1;
    }
    newton_next = false;
    const bool plain_step = (d == x);
    if (plain_step && S.count == 3) d = face_direction(S, x);

    const SupportPoint<T> s = D.support(-d);
    const T d_norm = norm3(d);
    const T lb = dot3(s.w, d) / d_norm;  // every y in D has <y, d/|d|> >= lb
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
    // Newton's point is always added (wide_gjk.inl says why); momentum's is skipped in these two cases.
    if (!plain_step && !newton_step && xn - lower_bound <= tol) {
      momentum = false;
      continue;
    }
    if (!plain_step && !newton_step && xx - dot3(x, s.w) <= tol * xn) {
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
      if (!plain_step) { momentum = false; newton = false; continue; }
      r.status = xn <= T(2) * params.touch_tolerance ? GjkStatus::overlap : GjkStatus::stalled;
      break;
    }
    // Momentum whose step moves |x| by less than the tolerance is lagging behind the gradient (delta_k -> 1
    // makes the direction sluggish near a flat contact): finish with plain GJK steps, as Montaut et al. do.
    // Likewise when its support points stopped improving the lower bound (a simple adaptive restart, after
    // O'Donoghue and Candes, "Adaptive restart for accelerated gradient schemes", 2015).
    const T next_xn = std::sqrt(next_xx);
    if (!plain_step && (xn - next_xn <= tol || stale >= kMaxStaleMomentumSteps)) momentum = false;
    S = next;
    x = proj.x;
    d_prev = d;
    last_s = s.w;
    // Newton's direction for the next iteration (wide_gjk.inl: when, and why).
    if (newton) {  // polytope pairs too whatever the sign of lb (wide_gjk.inl)
      const T inv_norm = T(1) / d_norm;
      const Vec3<T> n(inv_norm * d.x(), inv_norm * d.y(), inv_norm * d.z());
      T step2 = T(0);
      Vec3<T> nd;
      T shrunk;
      if (flat_pair) {
        nd = feature_direction(D, S, n, s, step2);
        // The tilt towards x's offset from the line along nd (wide_gjk.inl says why).
        const Vec3<T> t = wsub(x, wscale(dot3(x, nd) / dot3(nd, nd), nd));
        const T tn = std::sqrt(dot3(t, t));
        const T eps = std::sqrt((T(0.2) * tol) / norm3(s.w));
        if (tn > T(0)) nd = wadd(nd, wscale(eps / tn, t));
        shrunk = T(0.25) * newton_step2 + T(4) * (eps * eps);
      } else {
        const Vec3<T> res(s.w.x() - lb * n.x(), s.w.y() - lb * n.y(), s.w.z() - lb * n.z());
        nd = newton_direction(D, n, s, res, lb, step2);
        shrunk = T(0.25) * newton_step2;
      }
      const bool valid = flat_pair || lb > T(0);
      const bool failed = newton_step && !(valid && step2 <= shrunk);
      bool skip = false;  // flat pairs: a failed step skips one Newton choice instead of ending them
      if (flat_pair) {
        const T gap = next_xn - lower_bound;
        skip = failed || (newton_step && !(gap <= T(0.5) * newton_gap));
        newton_gap = gap;
      } else if (failed) {
        newton = false;
      }
      if (newton && !skip && valid && step2 <= T(kNewtonSwitch * kNewtonSwitch) &&
          next_xn - lower_bound > T(kNewtonPlainGap) * tol) {
        newton_dir = nd;
        newton_step2 = step2;
        newton_next = true;
      }
    }
  }
  // The budget can run out right after x reached the origin.
  if (r.status == GjkStatus::max_iterations && norm3(x) <= params.touch_tolerance) r.status = GjkStatus::overlap;
  r.x = x;
  r.lower_bound = lower_bound;
  if (r.status == GjkStatus::overlap) r.x = Vec3<T>::Zero();
  return r;
}

}  // namespace batchcol::test_reference
