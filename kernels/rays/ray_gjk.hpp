// Ray casting against any convex shape given by its support function: the GJK ray cast of G. van den Bergen,
// "Ray casting against general convex objects with application to continuous collision detection", JGT 2004
// (Algorithm 1, with the margin handled on the core as in sec. 4 of that paper). Used for the inflated shapes without
// an exact kernel (box, cylinder, cone, ellipsoid, hull and triangle with inflation > 0).
//
// Certificate: lambda only moves to the plane of a support point that separates the current point x from the shape,
// so x(lambda) never enters the shape and lambda <= the exact hit. The loop stops when the simplex point v, whose norm
// bounds the distance from x to the core from above, certifies that distance <= radius + eps: the reported hit point
// is outside the shape and within eps of it. A miss is certified by a separating plane the ray moves away from.
#pragma once

#include "kernels/rays/ray_interval.hpp"
#include "kernels/support.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace batchcol::kernels::rays {

/// The closest point to the origin of conv(y[0..n)) and the weights of the points it uses (others get 0).
/// Region tests after Ericson, "Real-Time Collision Detection" (2005), sec. 5.1.5-5.1.6; the tetrahedron is solved
/// as "inside, or the closest of its four faces".
template <class T> struct SimplexPoint {
  Vec3<T> v = Vec3<T>::Zero();
  std::array<T, 4> w{};
};

template <class T> SimplexPoint<T> closest_on_segment(const Vec3<T>& a, const Vec3<T>& b, int ia, int ib) {
  SimplexPoint<T> r;
  const Vec3<T> ab = b - a;
  const T den = norm2(ab);
  T s = den > T(0) ? -dot3(a, ab) / den : T(0);
  s = std::min(std::max(s, T(0)), T(1));
  r.v = a + s * ab;
  r.w[ia] = T(1) - s, r.w[ib] = s;
  return r;
}

template <class T> SimplexPoint<T> closest_on_triangle(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c, int ia,
                                                       int ib, int ic) {
  SimplexPoint<T> r;
  const Vec3<T> ab = b - a, ac = c - a, ap = -a;
  const T d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= T(0) && d2 <= T(0)) { r.v = a, r.w[ia] = T(1); return r; }
  const Vec3<T> bp = -b;
  const T d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= T(0) && d4 <= d3) { r.v = b, r.w[ib] = T(1); return r; }
  const T vc = d1 * d4 - d3 * d2;
  if (vc <= T(0) && d1 >= T(0) && d3 <= T(0)) return closest_on_segment(a, b, ia, ib);
  const Vec3<T> cp = -c;
  const T d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= T(0) && d5 <= d6) { r.v = c, r.w[ic] = T(1); return r; }
  const T vb = d5 * d2 - d1 * d6;
  if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) return closest_on_segment(a, c, ia, ic);
  const T va = d3 * d6 - d5 * d4;
  if (va <= T(0) && (d4 - d3) >= T(0) && (d5 - d6) >= T(0)) return closest_on_segment(b, c, ib, ic);
  const T den = va + vb + vc;
  if (!(den > T(0))) return closest_on_segment(a, b, ia, ib);  // degenerate (collinear) triangle
  const T sv = vb / den, sw = vc / den;
  r.v = a + sv * ab + sw * ac;
  r.w[ia] = T(1) - sv - sw, r.w[ib] = sv, r.w[ic] = sw;
  return r;
}

/// The faces of a tetrahedron: three vertices and the opposite one.
constexpr int kTetraFace[4][4] = {{1, 2, 3, 0}, {0, 2, 3, 1}, {0, 1, 3, 2}, {0, 1, 2, 3}};

template <class T> SimplexPoint<T> closest_on_simplex(const Vec3<T>* y, int n) {
  if (n == 1) {
    SimplexPoint<T> r;
    r.v = y[0], r.w[0] = T(1);
    return r;
  }
  if (n == 2) return closest_on_segment(y[0], y[1], 0, 1);
  if (n == 3) return closest_on_triangle(y[0], y[1], y[2], 0, 1, 2);
  // Tetrahedron: the origin is inside when it is on the inner side of all four faces.
  bool inside = true;
  SimplexPoint<T> best;
  T best_d = infinity<T>();
  for (const auto& f : kTetraFace) {
    const Vec3<T> nrm = cross3<T>(y[f[1]] - y[f[0]], y[f[2]] - y[f[0]]);
    const T side_o = -dot3(nrm, y[f[0]]), side_v = dot3<T>(nrm, y[f[3]] - y[f[0]]);
    if (side_o * side_v >= T(0) && side_v != T(0)) continue;  // origin on the opposite vertex's side of this face
    inside = false;
    const SimplexPoint<T> p = closest_on_triangle(y[f[0]], y[f[1]], y[f[2]], f[0], f[1], f[2]);
    const T dp = norm2(p.v);
    if (dp < best_d) best_d = dp, best = p;
  }
  if (inside) {
    SimplexPoint<T> r;  // v = 0; the weights are not needed (the loop stops)
    r.w = {T(1), T(1), T(1), T(1)};
    return r;
  }
  return best;
}

struct RayGjkSettings {
  double tolerance = 1e-9;  // eps above, in metres; raised to the arithmetic's floor (see ray_gjk)
  int max_iterations = 64;
};

/// Ray cast against core(s) + ball(radius), radius > 0. The simplex is kept on the core (van den Bergen's margin
/// variant: a polytope core converges in finitely many steps, a curved one like GJK's distance): with p = support of
/// the core along v and w = x - p, the plane <v, y> = <v, p> + radius |v| supports the inflated shape, and x is beyond
/// it when <v, w> > radius |v|. Stops when the distance from x to the core is certified <= radius + eps: either |v|
/// (>= that distance, v being a point of x - core) is, or the duality gap |v|^2 - <v, w> <= eps |v| proves |v| <=
/// radius + eps after a step that did not advance. `bound` is a bounding radius of the shape about its origin.
template <class T> LocalHit<T> ray_gjk(const ShapeCore<T>& s, T radius, T bound, const Vec3<T>& o, const Vec3<T>& d,
                                       T t_max, const RayGjkSettings& settings) {
  // Coordinates of x - p are as large as |o| + bound near the end: below ~64 ulps of that, |v| is rounding noise.
  const T eps = std::max(T(settings.tolerance), T(64) * machine_epsilon<T>() * (norm3(o) + bound));
  const T reach = radius + eps;
  SupportHint hint;
  LocalHit<T> h;
  T lambda = T(0);
  Vec3<T> x = o, normal = Vec3<T>::Zero();
  Vec3<T> v = x - s.center();
  std::array<Vec3<T>, 4> P;  // core support points of the current simplex
  int n = 0;
  bool done = false;
  int stalls = 0;
  for (int it = 0; it < settings.max_iterations && !done; ++it) {
    const T vv = norm2(v);
    if (vv <= reach * reach) {
      done = true;
      break;
    }
    const T nv = std::sqrt(vv);
    const Vec3<T> p = support(s, v, hint);
    const Vec3<T> w = x - p;
    const T vw = dot3(v, w);
    const bool advance = vw > radius * nv;
    if (advance) {
      const T vr = dot3(v, d);
      if (vr >= T(0)) return h;  // separating plane, and the ray moves away from it
      lambda -= (vw - radius * nv) / vr;
      if (lambda > t_max) return h;
      x = o + lambda * d;
      normal = v;
    } else if (vv - vw <= eps * nv) {
      done = true;  // the gap certifies |v| <= radius + eps (see above)
      break;
    }
    bool duplicate = false;  // a repeated support point would make the simplex degenerate
    for (int i = 0; i < n; ++i) duplicate = duplicate || P[i] == p;
    if (!duplicate) P[n++] = p;
    std::array<Vec3<T>, 4> Y;
    for (int i = 0; i < n; ++i) Y[i] = x - P[i];
    const SimplexPoint<T> sp = closest_on_simplex(Y.data(), n);
    int kept = 0;
    for (int i = 0; i < n; ++i)
      if (sp.w[i] > T(0)) P[kept++] = P[i];
    n = kept;
    if (n == 4) {
      v = sp.v;
      done = true;  // x inside the core (only when the origin starts there)
    } else if (!advance && norm2(sp.v) >= vv * (T(1) - T(64) * machine_epsilon<T>())) {
      // No progress: on nearly degenerate simplices (a cone's apex and neighbouring rim points) the projection's
      // rounding can drop the new point forever while the gap stays just above eps |v|. Restart the simplex from the
      // newest support point (it keeps x's certificates: x and lambda do not change); give up after a few restarts.
      if (++stalls > 4) break;
      P[0] = p, n = 1, v = x - p;
    } else {
      v = sp.v;
    }
  }
  if (!done) done = norm2(v) <= reach * reach;
  h.hit = true;
  h.t = lambda;
  h.status = done ? LocalStatus::converged : LocalStatus::max_iterations;
  const T nn = norm3(normal);
  h.normal = nn > T(0) ? Vec3<T>(normal / nn) : Vec3<T>(-d / norm3(d));  // never advanced: the origin is inside
  return h;
}

}  // namespace batchcol::kernels::rays
