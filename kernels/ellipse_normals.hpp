// The normals of an ellipse at the feet of the perpendiculars from a point: every critical point of the distance
// from q = (x0, y0) to the ellipse (x/a)^2 + (y/b)^2 = 1 (up to four). Used by kernels/segment_depth.hpp, where
// a cylinder's or cone's rim circle, seen along a segment, is such an ellipse.
//
// Lagrange: q - x = t (x / a^2, y / b^2), so x = a^2 x0 / (t + a^2), y = b^2 y0 / (t + b^2), and t is a root of
//   F(t) = (a x0 / (t + a^2))^2 + (b y0 / (t + b^2))^2 - 1.
// With a >= b, F is convex on each of (-inf, -a^2), (-a^2, -b^2) and (-b^2, inf) (a sum of 1 / (t + c)^2 terms):
// increasing from -1 to +inf on the first, decreasing from +inf to -1 on the last (one root each), convex with
// +inf at both poles on the middle one (zero or two roots, bracketed by its minimum, found by bisection on the
// monotone F'). Bisection on each bracket finds every root, which a sampled search cannot promise (two roots
// merge where q crosses the ellipse's evolute). The normal at a foot is (x0 / (t + a^2), y0 / (t + b^2)) up to a
// positive factor. The caller evaluates its objective at the normals, so a direction error e costs only ~e^2.
// A zero x0 or y0 removes a pole; the axis vertices (normals +-x, +-y), which are then feet too, are left to the
// caller.
#pragma once

#include <cmath>
#include <utility>

namespace batchcol::kernels {

template <class T> struct EllipseNormals {
  int count = 0;
  T nx[4] = {}, ny[4] = {};  // not normalised
};

namespace detail {

template <class T> struct EllipseFootFunction {
  T a2, b2, ax, by;  // a^2, b^2, a x0, b y0
  static T term(T c, T t) { return c == T(0) ? T(0) : (c / t) * (c / t); }
  T F(T t) const { return term(ax, t + a2) + term(by, t + b2) - T(1); }
  T dF(T t) const {  // only inside the intervals (no pole)
    const T u = t + a2, v = t + b2;
    return -T(2) * (ax * ax / (u * u * u) + by * by / (v * v * v));
  }
};

/// Bisection to the last representable midpoint; `lo` and `hi` bracket a sign change of g.
template <class T, class G> T bisect(const G& g, T lo, T hi) {
  const bool lo_positive = g(lo) > T(0);
  for (int i = 0; i < 300; ++i) {
    const T mid = lo + (hi - lo) / T(2);
    if (!(mid > lo && mid < hi)) break;
    (g(mid) > T(0)) == lo_positive ? lo = mid : hi = mid;
  }
  return lo + (hi - lo) / T(2);
}

}  // namespace detail

/// Feet normals from (x0, y0) on the ellipse with semi-axes a (along x) and b (along y), both > 0.
template <class T> EllipseNormals<T> ellipse_normals(T a, T b, T x0, T y0) {
  EllipseNormals<T> out;
  const bool swapped = a < b;
  if (swapped) std::swap(a, b), std::swap(x0, y0);
  if (!(b > T(0)) || !std::isfinite(a) || (x0 == T(0) && y0 == T(0))) return out;
  const detail::EllipseFootFunction<T> f{a * a, b * b, a * x0, b * y0};
  const auto F = [&](T t) { return f.F(t); };
  const auto add = [&](T t) {
    const T nx = x0 / (t + f.a2), ny = y0 / (t + f.b2);
    if (!std::isfinite(nx) || !std::isfinite(ny)) return;
    out.nx[out.count] = swapped ? ny : nx;
    out.ny[out.count] = swapped ? nx : ny;
    ++out.count;
  };
  // Beyond M of the poles each term is at most 1/4, so F <= -1/2 there: finite ends of the outer brackets.
  const T M = T(2) * (std::abs(f.ax) + std::abs(f.by));
  const T left = -f.a2 - M - (f.a2 - f.b2), right = -f.b2 + M;
  if (F(-f.a2) > T(0) && F(left) < T(0)) add(detail::bisect(F, left, -f.a2));
  if (F(-f.b2) > T(0) && F(right) < T(0)) add(detail::bisect(F, -f.b2, right));
  if (f.a2 > f.b2) {
    // The minimum of F on (-a^2, -b^2): the root of the increasing F' (a pole-free interior point at each step).
    const auto dF = [&](T t) { return t <= -f.a2 ? -T(1) : t >= -f.b2 ? T(1) : f.dF(t); };
    const T t_min = detail::bisect(dF, -f.a2, -f.b2);
    if (t_min > -f.a2 && t_min < -f.b2 && F(t_min) < T(0)) {
      if (F(-f.a2) > T(0)) add(detail::bisect(F, -f.a2, t_min));
      if (F(-f.b2) > T(0)) add(detail::bisect(F, t_min, -f.b2));
    }
  }
  return out;
}

}  // namespace batchcol::kernels
