// The scalar transcription of kernels/simd/wide_gjk_start_gate.inl (the reasoning is there): whether a pair's
// cores certainly overlap, from its first support point, with the wide code's operations in the same order. Where
// they do, no closed-form start candidate can separate them, and the reference's gjk() does not compute one.
// Included by reference_gjk.hpp.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// wide_gjk_start_gate.inl's kGateShrink.
template <class T> constexpr T kGateShrink = T(1) - T(1e-6);

/// wide_gjk_start_gate.inl's core_contains(): q (the core's frame) inside the core shrunk by kGateShrink.
template <class T> bool core_contains(const ShapeCore<T>& s, const Vec3<T>& q) {
  const T k = kGateShrink<T>;
  const T s0 = s.size.x(), s1 = s.size.y(), s2 = s.size.z();
  const T x = q.x(), y = q.y(), z = q.z();
  const auto abs = [](T v) { return v < T(0) ? -v : v; };
  switch (s.type) {
    case ShapeType::box: return abs(x) < k * s0 && abs(y) < k * s1 && abs(z) < k * s2;
    case ShapeType::cylinder: {
      const T r = k * s0;
      return abs(z) < k * s1 && x * x + y * y < r * r;
    }
    case ShapeType::cone: {
      const T h = k * s1, e = (k * s0) * (h - z), h2 = s1 + s1;
      return z > -h && e > T(0) && (h2 * h2) * (x * x + y * y) < e * e;
    }
    case ShapeType::ellipsoid: {
      const T u = x * (s1 * s2), v = y * (s0 * s2), w = z * (s0 * s1);
      const T p = (s0 * s1) * s2;
      return (u * u + v * v) + w * w < (k * p) * p;
    }
    default: return false;
  }
}

/// wide_gjk_start_gate.inl's cores_overlap(): p.a (A's frame) inside B, or p.b (A's frame) inside A; p is the
/// pair's first support point.
template <class T> bool cores_overlap(const MinkowskiDifference<T>& D, const SupportPoint<T>& p) {
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  const Vec3<T> v(p.a.x() - t.x(), p.a.y() - t.y(), p.a.z() - t.z());
  const Vec3<T> q((R(0, 0) * v.x() + R(1, 0) * v.y()) + R(2, 0) * v.z(),
                  (R(0, 1) * v.x() + R(1, 1) * v.y()) + R(2, 1) * v.z(),
                  (R(0, 2) * v.x() + R(1, 2) * v.y()) + R(2, 2) * v.z());
  return core_contains(*D.B, q) || core_contains(*D.A, p.b);
}

}  // namespace batchcol::test_reference
