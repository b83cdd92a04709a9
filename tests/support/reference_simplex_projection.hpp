// Reference for the tests (with reference_gjk.hpp). Projection of the origin onto the convex hull of 1-4 points: the "fully corrective" step of GJK seen as
// Frank-Wolfe. Signed-volume sub-algorithm after Montanari, Petrinic, Barbieri, "Improving the GJK algorithm for
// faster and more reliable distance queries between convex objects", ACM TOG 36(3), 2017: barycentric coordinates
// are ratios of signed sub-volumes (a triangle's: signed sub-areas times |n|, as triple products with its normal n),
// so whenever the origin is classified inside, the weights are non-negative and sum to one: the result is a convex
// combination even on nearly degenerate simplices, and exactly degenerate ones (zero volume / area / length) fall
// back to their faces.
// As in GJK's classic Voronoi-region form, only sub-simplices that keep the newest vertex are candidates: 2 edges per
// triangle, and per tetrahedron the faces through the newest vertex that the origin sees (at most 3), visited in a
// fixed order. The SIMD kernel (kernels/simd/wide_gjk.inl) runs the triangle on all lanes at once and the
// tetrahedron's one face and three edges on all lanes at once, with the same arithmetic.
#pragma once

#include "kernels/math.hpp"

#include <array>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// Closest point of a simplex to the origin as a convex combination of a subset of its vertices.
template <class T> struct SimplexProjection {
  Vec3<T> x = Vec3<T>::Zero();
  int count = 0;                    // size of the support set
  std::array<int, 4> index{};       // input indices of the support set
  std::array<T, 4> lambda{};        // their weights (>= 0, sum 1)
  bool contains_origin = false;     // only for 4 points: origin inside the tetrahedron
};

namespace detail {

template <class T> SimplexProjection<T> vertex(const Vec3<T>* p, int i) {
  SimplexProjection<T> r;
  r.x = p[i];
  r.count = 1;
  r.index[0] = i;
  r.lambda[0] = T(1);
  return r;
}

template <class T> SimplexProjection<T> segment(const Vec3<T>* p, int i, int j) {
  const Vec3<T> t = p[j] - p[i];
  const T tt = norm2(t);
  if (tt == T(0)) return vertex(p, i);  // duplicate points
  const T u = -dot3(p[i], t) / tt;        // parameter of the origin's projection on the line
  if (u <= T(0)) return vertex(p, i);
  if (u >= T(1)) return vertex(p, j);
  SimplexProjection<T> r;
  r.count = 2;
  r.index = {i, j, 0, 0};
  r.lambda = {T(1) - u, u, T(0), T(0)};
  r.x = r.lambda[0] * p[i] + r.lambda[1] * p[j];
  return r;
}

template <class T> const SimplexProjection<T>& closer(const SimplexProjection<T>& a, const SimplexProjection<T>& b) {
  return norm2(b.x) < norm2(a.x) ? b : a;
}

template <class T> bool opposite_sign(T a, T b) { return (a > T(0) && b < T(0)) || (a < T(0) && b > T(0)); }

/// Triangle p[i], p[j], p[k] with p[k] the newest vertex: the closest point over the face and the two edges that
/// keep k. (Edge i-j and the old vertices belong to the previous simplex, whose closest point x GJK already has:
/// they cannot bring |x| down, so GJK never needs them.) Edges are oriented old -> new and visited i-k, then j-k.
template <class T> SimplexProjection<T> triangle(const Vec3<T>* p, int i, int j, int k) {
  // The normal from the edges at the newest vertex, (p_i - p_k) x (p_j - p_k): the tetrahedron's faces keeping
  // vertex 3 use the same products for their visibility rule and signed volumes (wide_gjk.inl's Plane).
  const Vec3<T> a = p[i] - p[k], b = p[j] - p[k];
  const Vec3<T> n = cross3<T>(a, b);
  const T nn = norm2(n);
  const auto edges = [&] { return closer(segment(p, i, k), segment(p, j, k)); };
  if (nn == T(0)) return edges();  // collinear: the closest point lies on an edge
  // Weights of the origin's projection p0 = t n on the plane: C_m = <n, (p_J - p0) x (p_K - p0)> (the signed area
  // of the sub-triangle opposite vertex m, times |n|), whose sum is |n|^2. With r = p_k - p0 and the edges at p_k,
  // a = p_i - p_k, b = p_j - p_k: C_i = <n, b x r> = <r, n x b>, C_j = <r, a x n>, and C_k = |n|^2 - C_i - C_j:
  // the same weights without a coordinate plane or a fourth area. r, not p_k: near a contact GJK's triangles are
  // long slivers far from the origin next to |x|, and <p_k, n x b> rounds like eps |p_k| |n| |b| where the
  // signed areas (and these) round like eps |p_k - p0| |n| |b| (measured with <p_k, .>: the test
  // WideGjk.BoxCylinderAndConeRimAndSideContactsStartInClosedForm stalled 1.025e-9 off its 1e-9 bound; in 4000
  // of its pairs 5 stalls beyond 1e-9 against 1 for the areas, 1 with r).
  const Vec3<T> r = p[k] - n * (dot3(p[k], n) / nn);
  const T Ci = dot3(r, cross3<T>(n, b)), Cj = dot3(r, cross3<T>(a, n));
  const std::array<T, 3> C = {Ci, Cj, (nn - Ci) - Cj};
  // The total is |n|^2 > 0: inside when no weight is negative (then their sum is positive: the division is safe).
  const bool inside = !(C[0] < T(0)) && !(C[1] < T(0)) && !(C[2] < T(0));
  if (inside) {
    SimplexProjection<T> r;
    r.count = 3;
    const std::array<int, 3> id = {i, j, k};
    const T inv = T(1) / (C[0] + C[1] + C[2]);  // one division (wide_gjk.inl's face() says why)
    for (int m = 0; m < 3; ++m) { r.index[m] = id[m]; r.lambda[m] = C[m] * inv; }
    r.x = r.lambda[0] * p[i] + r.lambda[1] * p[j] + r.lambda[2] * p[k];
    return r;
  }
  // Outside: the closest point is on an edge whose opposite vertex has a negative weight (edge i-k is opposite j,
  // edge j-k opposite i). When neither has (the origin lies beyond edge i-j), both are candidates.
  const bool via_i = C[1] < T(0), via_j = C[0] < T(0);
  if (via_i == via_j) return edges();
  return via_i ? segment(p, i, k) : segment(p, j, k);
}

template <class T> T det3(const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c) { return dot3(a, cross3(b, c)); }

/// Tetrahedron p[0..3] with p[3] the newest vertex: the origin inside, or the closest point over the faces that
/// keep vertex 3 and that the origin sees. When the origin sees only the old face 0-1-2, nothing keeping vertex 3
/// is closer than GJK's current x: the result is "no candidate" (x infinite, count 0).
template <class T> SimplexProjection<T> tetrahedron(const Vec3<T>* p) {
  // V[m] = signed volume of the tetrahedron with vertex m replaced by the origin; their sum is the full volume.
  // For m < 3 it is the triple product <p3, (p_I - p3) x (p_J - p3)> (= <p3, p_I x p_J>, up to the sign) with the
  // normal n_m of face m, which the visibility rule below and triangle() compute in the same way.
  const std::array<std::array<int, 2>, 3> old = {{{1, 2}, {0, 2}, {0, 1}}};
  std::array<Vec3<T>, 3> n;
  std::array<T, 3> sn;
  for (int m = 0; m < 3; ++m) {
    n[m] = cross3<T>(p[old[m][0]] - p[3], p[old[m][1]] - p[3]);
    sn[m] = dot3(p[3], n[m]);
  }
  const std::array<T, 4> V = {sn[0], -sn[1], sn[2], -det3(p[0], p[1], p[2])};
  const T total = V[0] + V[1] + V[2] + V[3];
  bool inside = total != T(0);
  for (T vm : V) inside = inside && !opposite_sign(vm, total);
  if (inside) {
    SimplexProjection<T> r;
    r.count = 4;
    r.contains_origin = true;
    for (int m = 0; m < 4; ++m) { r.index[m] = m; r.lambda[m] = V[m] / total; }
    r.x = Vec3<T>::Zero();
    return r;
  }
  // Outside (or flat): faces m = 0, 1, 2 (face m omits vertex m) that the origin sees, i.e. whose opposite weight
  // has the wrong sign; a flat tetrahedron (total == 0) has no orientation, so all three are candidates.
  const auto candidate = [&](int m) { return total == T(0) || opposite_sign(V[m], total); };
  // First the visible face whose plane is farthest from the origin (squared distance s (s / nn), the first of
  // equal ones): when the origin's projection on it lies inside it, it is the answer, since the plane of a face
  // supports the tetrahedron and no point of it is closer than that plane. On smooth shapes the newest vertex
  // raises a flat tent over the old face and the origin sees all three new faces: this spares the other two.
  int first = -1;
  T far = T(0);
  for (int m = 0; m < 3; ++m) {
    if (!candidate(m)) continue;
    const T nn = norm2(n[m]), s = sn[m];
    const T q = nn > T(0) ? s * (s / nn) : T(-1);
    if (first < 0 || q > far) first = m, far = q;
  }
  if (first >= 0) {
    const SimplexProjection<T> f = triangle(p, old[first][0], old[first][1], 3);
    if (f.count == 3) return f;
  }
  // Its projection fell outside it: the closest point is on an edge k-3 of a visible face. No other visible face's
  // interior can hold it: that face's plane would then be as far from the origin as the closest point (it supports
  // the tetrahedron), and no visible plane is farther than the closest point, so the first face would be that face
  // or one at the same distance, whose projection is the same point (inside it, up to rounding on an edge, where
  // the edge answers it). Each face's own answer (triangle()) is the closest point of one of its two edges k-3
  // (in exact arithmetic the closest point of the face), so the closest of all those edges is at least as close
  // as any face's answer, without a triangle() per face: edge k belongs to the visible faces that hold old vertex
  // k (face m holds every old vertex but m), visited in order, the first of equal ones kept.
  SimplexProjection<T> best;
  best.x = Vec3<T>::Constant(std::numeric_limits<T>::infinity());
  bool have = false;
  for (int k = 0; k < 3; ++k) {
    if (!candidate((k + 1) % 3) && !candidate((k + 2) % 3)) continue;
    const SimplexProjection<T> e = segment(p, k, 3);
    best = have ? closer(best, e) : e;
    have = true;
  }
  return best;
}

}  // namespace detail

/// GJK's projection step: the closest point to the origin of conv(p[0..n-1]), 1 <= n <= 4, over the sub-simplices
/// that keep the newest vertex p[n-1] (the others are faces of the previous simplex, which cannot be closer than
/// GJK's current x), plus the old vertex p[0] for a segment. count == 0 (x infinite): no such candidate is visible.
template <class T> SimplexProjection<T> project_origin(const Vec3<T>* p, int n) {
  switch (n) {
    case 1: return detail::vertex(p, 0);
    case 2: return detail::segment(p, 0, 1);
    case 3: return detail::triangle(p, 0, 1, 2);
    default: return detail::tetrahedron(p);
  }
}

}  // namespace batchcol::test_reference
