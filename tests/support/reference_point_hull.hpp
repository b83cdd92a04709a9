// The scalar transcription of kernels/simd/wide_gjk_point_hull.inl (the reasoning is there): a sphere-hull pair's
// start point, the sphere centre's nearest point on the hull's most separating face, with the wide code's
// operations in the same order. Included by reference_gjk.hpp.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"
#include "kernels/support.hpp"

#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// wide_gjk_point_hull.inl's point_hull_takes().
inline bool point_hull_takes(const HullView& h) {
  return h.vertex_count < kHillClimbMinVertices && h.face_count >= 1 && h.face_count <= kPointHullMaxFaces &&
         h.faces != nullptr && h.face_normals != nullptr;
}

/// wide_gjk_point_hull.inl's triangle_point(): c's nearest point on triangle (a, b, e), Ericson's region order.
template <class T>
Vec3<T> triangle_point(const Vec3<T>& c, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& e) {
  const auto sub = [](const Vec3<T>& p, const Vec3<T>& q) { return Vec3<T>(p.x() - q.x(), p.y() - q.y(), p.z() - q.z()); };
  const auto along = [](const Vec3<T>& p, T u, const Vec3<T>& d) {
    return Vec3<T>(p.x() + u * d.x(), p.y() + u * d.y(), p.z() + u * d.z());
  };
  const Vec3<T> ab = sub(b, a), ae = sub(e, a), ap = sub(c, a), bp = sub(c, b), ep = sub(c, e);
  const T d1 = dot3(ab, ap), d2 = dot3(ae, ap), d3 = dot3(ab, bp), d4 = dot3(ae, bp), d5 = dot3(ab, ep), d6 = dot3(ae, ep);
  const T ve = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (d1 <= T(0) && d2 <= T(0)) return a;
  if (d3 >= T(0) && d4 <= d3) return b;
  if (ve <= T(0) && d1 >= T(0) && d3 <= T(0)) return along(a, d1 / (d1 - d3), ab);
  if (d6 >= T(0) && d5 <= d6) return e;
  if (vb <= T(0) && d2 >= T(0) && d6 <= T(0)) return along(a, d2 / (d2 - d6), ae);
  const T d43 = d4 - d3, d56 = d5 - d6;
  if (va <= T(0) && d43 >= T(0) && d56 >= T(0)) return along(b, d43 / (d43 + d56), sub(e, b));
  const T inv = T(1) / ((va + vb) + ve);
  return along(along(a, vb * inv, ab), ve * inv, ae);
}

/// wide_gjk_point_hull.inl's point_hull_candidate() for one pair of a point_hull_pair() type: false where the hull
/// takes none or the candidate is not finite; else its points of A and B (A's frame) and w.
template <class T> bool point_hull_candidate(const MinkowskiDifference<T>& D, SupportPoint<T>& p) {
  const bool sphere_a = D.A->type == ShapeType::sphere;
  const HullView& h = *(sphere_a ? D.B : D.A)->hull;
  if (!point_hull_takes(h)) return false;
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  const Vec3<T> c = sphere_a ? Vec3<T>(-((R(0, 0) * t.x() + R(1, 0) * t.y()) + R(2, 0) * t.z()),
                                       -((R(0, 1) * t.x() + R(1, 1) * t.y()) + R(2, 1) * t.z()),
                                       -((R(0, 2) * t.x() + R(1, 2) * t.y()) + R(2, 2) * t.z()))
                             : t;
  const T dx = c.x() - T(h.centroid[0]), dy = c.y() - T(h.centroid[1]), dz = c.z() - T(h.centroid[2]);
  const T reach = T(kPointHullNearRadii) * T(h.radius);
  if (!((dx * dx + dy * dy) + dz * dz <= reach * reach)) return false;  // point_hull_near()
  T best = T(0);
  std::uint32_t best_face = 0;
  for (std::uint32_t f = 0; f < h.face_count; ++f) {
    const Vec3<T> v = hull_point<T>(h, h.faces[3 * f]);
    const double* nd = h.face_normals + 3 * f;
    const Vec3<T> n(static_cast<T>(nd[0]), static_cast<T>(nd[1]), static_cast<T>(nd[2]));
    const T s = (n.x() * (c.x() - v.x()) + n.y() * (c.y() - v.y())) + n.z() * (c.z() - v.z());
    if (f == 0 || s > best) best = s, best_face = f;
  }
  const std::uint32_t* face = h.faces + 3 * best_face;
  const Vec3<T> q = triangle_point(c, hull_point<T>(h, face[0]), hull_point<T>(h, face[1]), hull_point<T>(h, face[2]));
  if (sphere_a) {
    p.a = Vec3<T>::Zero();
    p.b = Vec3<T>(((R(0, 0) * q.x() + R(0, 1) * q.y()) + R(0, 2) * q.z()) + t.x(),
                  ((R(1, 0) * q.x() + R(1, 1) * q.y()) + R(1, 2) * q.z()) + t.y(),
                  ((R(2, 0) * q.x() + R(2, 1) * q.y()) + R(2, 2) * q.z()) + t.z());
  } else {
    p.a = q;
    p.b = t;
  }
  p.w = Vec3<T>(p.a.x() - p.b.x(), p.a.y() - p.b.y(), p.a.z() - p.b.z());
  return dot3(p.w, p.w) < std::numeric_limits<T>::infinity();
}

}  // namespace batchcol::test_reference
