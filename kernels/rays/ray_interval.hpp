// Ray intersection vocabulary shared by the per-shape kernels. Every kernel works in the shape's local frame on the
// ray x(t) = o + t d (d need not be unit: t is in units of |d|) and returns the parameter interval [enter, exit]
// where the line lies inside the closed solid, with the outward surface normal at `enter`. finish() turns that
// interval into the hit of the ray segment t in [0, t_max].
#pragma once

#include "kernels/math.hpp"

#include <limits>

namespace batchcol::kernels::rays {

template <class T> constexpr T infinity() { return std::numeric_limits<T>::infinity(); }

/// The line's interval inside a solid; empty when enter > exit (or NaN). `normal` is the outward unit normal at enter
/// when enter is finite.
template <class T> struct RayInterval {
  T enter = infinity<T>();
  T exit = -infinity<T>();
  Vec3<T> normal = Vec3<T>::Zero();

  bool empty() const { return !(enter <= exit); }
  static RayInterval everything() { return {-infinity<T>(), infinity<T>(), Vec3<T>::Zero()}; }
  static RayInterval nothing() { return {}; }
};

/// Outcome of one ray against one shape.
enum class LocalStatus : unsigned char { converged, max_iterations };

template <class T> struct LocalHit {
  bool hit = false;
  T t = quiet_nan<T>();
  Vec3<T> normal = Vec3<T>::Constant(quiet_nan<T>());  // unit, outward; -d/|d| when the origin is inside
  LocalStatus status = LocalStatus::converged;
};

/// Convention for a ray starting inside (or on) the solid: it hits at t = 0 with normal -d/|d| (there is no entry
/// surface; this is what a "how far can I go" query needs and what ray-cast GJK returns).
template <class T> LocalHit<T> finish(const RayInterval<T>& in, const Vec3<T>& d, T t_max) {
  LocalHit<T> h;
  if (in.empty() || in.exit < T(0) || in.enter > t_max) return h;
  h.hit = true;
  if (in.enter <= T(0)) {
    h.t = T(0);
    h.normal = -d / norm3(d);
  } else {
    h.t = in.enter;
    h.normal = in.normal;
  }
  return h;
}

/// Intersection of two intervals (a convex solid as the intersection of two): the normal of the later entry.
template <class T> RayInterval<T> intersect(const RayInterval<T>& a, const RayInterval<T>& b) {
  RayInterval<T> r;
  r.enter = a.enter >= b.enter ? a.enter : b.enter;
  r.normal = a.enter >= b.enter ? a.normal : b.normal;
  r.exit = a.exit <= b.exit ? a.exit : b.exit;
  return r;
}

/// Union of two overlapping intervals (a convex solid as the union of convex pieces: the union along a line is one
/// interval): the normal of the earlier entry; `a` wins ties.
template <class T> RayInterval<T> unite(const RayInterval<T>& a, const RayInterval<T>& b) {
  if (b.empty()) return a;
  if (a.empty()) return b;
  RayInterval<T> r;
  r.enter = a.enter <= b.enter ? a.enter : b.enter;
  r.normal = a.enter <= b.enter ? a.normal : b.normal;
  r.exit = a.exit >= b.exit ? a.exit : b.exit;
  return r;
}

/// The slab lo <= o_i + t d_i <= hi along one axis; `axis_normal` is the outward normal of the hi face.
template <class T> RayInterval<T> slab(T o, T d, T lo, T hi, const Vec3<T>& axis_normal) {
  if (d == T(0)) return (o >= lo && o <= hi) ? RayInterval<T>::everything() : RayInterval<T>::nothing();
  const T t_lo = (lo - o) / d, t_hi = (hi - o) / d;
  RayInterval<T> r;
  if (d > T(0)) {  // enters through lo, leaves through hi
    r.enter = t_lo, r.exit = t_hi, r.normal = -axis_normal;
  } else {
    r.enter = t_hi, r.exit = t_lo, r.normal = axis_normal;
  }
  return r;
}

}  // namespace batchcol::kernels::rays
