// Analytic kernels for the pairs that have one. They are exact up to rounding, so they also serve as references
// for GJK/EPA in the tests. All work in the local frame of shape A with B placed by `b_in_a`.
//   - point/segment cores with swept radii: sphere-sphere, sphere-capsule, capsule-capsule (closest points of two
//     segments, clamped parametric solution of the 2x2 normal equations);
//   - sphere-box: clamp the centre to the box, or leave through the nearest face when inside;
//   - box-box boolean: separating-axis theorem over the 15 candidate axes (Gottschalk, Lin, Manocha, "OBBTree",
//     SIGGRAPH 1996);
//   - halfspace against any core: the support point in the direction opposite to the normal.
#pragma once

#include "kernels/pair_output.hpp"
#include "kernels/support.hpp"

namespace batchcol::kernels {

/// Segment cores closer than this many ulps of their coordinates touch: their offset is then rounding noise (a
/// few ulps) and its direction meaningless; 4096 ulps keeps the noise's angle below ~1e-3 rad when the rule does
/// not apply. Shared with the SIMD version (kernels/simd/wide_segments.inl).
constexpr double kSegmentTouchUlps = 4096;
/// The separating-axis test pads |R| by this many ulps so that the nine edge-edge axes of nearly parallel edges
/// (cross product ~ 0) cannot report a spurious separation from rounding: pairs closer than ~1e3 eps x size then
/// count as touching. Shared with the SIMD version (kernels/simd/wide_boxes.inl).
constexpr double kSatPaddingUlps = 1000;

/// Closest points of segments [p0, p1] and [q0, q1] (either may have zero length).
template <class T> void closest_points_segments(const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& q0,
                                                const Vec3<T>& q1, Vec3<T>& cp, Vec3<T>& cq) {
  const Vec3<T> d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const T a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const auto clamp01 = [](T v) { return std::min(std::max(v, T(0)), T(1)); };
  T s = T(0), t = T(0);
  if (a == T(0) && e == T(0)) {
  } else if (a == T(0)) {
    t = clamp01(f / e);
  } else {
    const T c = d1.dot(r);
    if (e == T(0)) {
      s = clamp01(-c / a);
    } else {
      const T b = d1.dot(d2);
      const T denom = a * e - b * b;  // >= 0; zero for parallel segments, where any s works: take s = 0
      s = denom > T(0) ? clamp01((b * f - c * e) / denom) : T(0);
      t = (b * s + f) / e;
      if (t < T(0)) { t = T(0); s = clamp01(-c / a); }
      else if (t > T(1)) { t = T(1); s = clamp01((b - c) / a); }
    }
  }
  cp = p0 + s * d1;
  cq = q0 + t * d2;
}

/// Two segment cores [p0, p1], [q0, q1] with swept radii: signed distance, witness points and normal (from the
/// first to the second). `centers` (second centre minus first) orients the normal when the cores touch.
template <class T>
PairOutput<T> segments_with_radii(const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& q0, const Vec3<T>& q1,
                                  T radius_a, T radius_b, const Vec3<T>& centers) {
  Vec3<T> ca, cb;
  closest_points_segments<T>(p0, p1, q0, q1, ca, cb);
  const Vec3<T> v = cb - ca;
  const T dcore = v.norm();
  const T coordinates = std::max(std::max(p0.cwiseAbs().maxCoeff(), p1.cwiseAbs().maxCoeff()),
                                 std::max(q0.cwiseAbs().maxCoeff(), q1.cwiseAbs().maxCoeff()));
  Vec3<T> n;
  if (dcore > T(kSegmentTouchUlps) * machine_epsilon<T>() * coordinates) {
    n = v / dcore;
  } else {
    // The cores touch: a unit vector orthogonal to both segments (the direction of least overlap when the
    // segments cross).
    const Vec3<T> axis_a = p1 - p0, axis_b = q1 - q0;
    const Vec3<T> c = axis_a.cross(axis_b);
    if (c.norm() > T(0)) n = c.normalized();
    else if (axis_a.norm() > T(0)) n = any_orthogonal(axis_a);
    else if (axis_b.norm() > T(0)) n = any_orthogonal(axis_b);
    else n = Vec3<T>::UnitX();
    if (n.dot(centers) < T(0)) n = -n;  // point from A towards B's centre when that is defined
  }
  PairOutput<T> out;
  out.status = Status::converged;
  out.distance = dcore - radius_a - radius_b;
  out.normal = n;
  out.witness_a = ca + radius_a * n;
  out.witness_b = cb - radius_b * n;
  return out;
}

/// Sphere/capsule against sphere/capsule: both cores are segments (a sphere's has zero length) along local z.
template <class T>
PairOutput<T> segment_cores(const ShapeCore<T>& A, const ShapeCore<T>& B, const Transform<T>& b_in_a) {
  const Vec3<T> ha(T(0), T(0), A.size.y()), hb(T(0), T(0), B.size.y());
  return segments_with_radii<T>(-ha, ha, b_in_a.apply(-hb), b_in_a.apply(hb), A.radius, B.radius, b_in_a.t);
}

/// Sphere core (a point at the origin of its frame) against a box core; `box_is_a` tells which one is A.
template <class T>
PairOutput<T> sphere_box(const ShapeCore<T>& sphere, const ShapeCore<T>& box, const Transform<T>& b_in_a,
                         bool box_is_a) {
  // Sphere centre in the box frame.
  const Vec3<T> c = box_is_a ? b_in_a.t : Vec3<T>(b_in_a.R.transpose() * (-b_in_a.t));
  const Vec3<T>& h = box.size;
  const Vec3<T> q = c.cwiseMax(-h).cwiseMin(h);
  Vec3<T> n, on_box;
  T dcore;
  if (q != c) {
    const Vec3<T> v = c - q;
    dcore = v.norm();
    n = v / dcore;
    on_box = q;
  } else {
    int axis = 0;
    Vec3<T> room = h - c.cwiseAbs();  // distance to the face on the centre's side, per axis
    if (room.y() < room[axis]) axis = 1;
    if (room.z() < room[axis]) axis = 2;
    const T sgn = c[axis] < T(0) ? T(-1) : T(1);
    n = Vec3<T>::Zero();
    n[axis] = sgn;
    on_box = c;
    on_box[axis] = sgn * h[axis];
    dcore = -room[axis];
  }
  // Everything so far is in the box frame with n pointing from the box to the sphere.
  const Vec3<T> p_box = on_box + box.radius * n, p_sphere = c - sphere.radius * n;
  PairOutput<T> out;
  out.status = Status::converged;
  out.distance = dcore - sphere.radius - box.radius;
  if (box_is_a) {
    out.normal = n;
    out.witness_a = p_box;
    out.witness_b = p_sphere;
  } else {
    out.normal = -(b_in_a.R * n);
    out.witness_a = b_in_a.apply(p_sphere);
    out.witness_b = b_in_a.apply(p_box);
  }
  return out;
}

/// Separating-axis test of two boxes (no inflation): true when they intersect or touch.
template <class T> bool boxes_intersect(const Vec3<T>& ha, const Vec3<T>& hb, const Transform<T>& b_in_a) {
  const Mat3<T>& R = b_in_a.R;
  const Vec3<T>& t = b_in_a.t;
  const Mat3<T> absR = R.cwiseAbs().array() + T(kSatPaddingUlps) * machine_epsilon<T>();
  for (int i = 0; i < 3; ++i)
    if (std::abs(t[i]) > ha[i] + hb.dot(absR.row(i))) return false;
  for (int j = 0; j < 3; ++j)
    if (std::abs(t.dot(R.col(j))) > ha.dot(absR.col(j)) + hb[j]) return false;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // Axis e_i x (R e_j), expressed in A's frame.
      const T dist = std::abs(t[i2] * R(i1, j) - t[i1] * R(i2, j));
      const T ra = ha[i1] * absR(i2, j) + ha[i2] * absR(i1, j);
      const T rb = hb[j1] * absR(i, j2) + hb[j2] * absR(i, j1);
      if (dist > ra + rb) return false;
    }
  }
  return true;
}

/// Halfspace A = {x : n.x <= offset} (its frame) against any bounded core B.
template <class T>
PairOutput<T> halfspace_shape(const ShapeCore<T>& half, const ShapeCore<T>& B, const Transform<T>& b_in_a) {
  const Vec3<T>& n = half.halfspace_normal;
  SupportHint hint;
  const Vec3<T> deepest = b_in_a.apply(support(B, Vec3<T>(b_in_a.R.transpose() * (-n)), hint));
  PairOutput<T> out;
  out.status = Status::converged;
  out.distance = n.dot(deepest) - half.halfspace_offset - half.radius - B.radius;
  out.normal = n;
  out.witness_b = deepest - B.radius * n;
  out.witness_a = out.witness_b - out.distance * n;
  return out;
}

/// Two halfspaces: they always intersect unless their normals are exactly opposite; the overlap is unbounded
/// (distance -infinity) unless they are antiparallel, where it is a slab of finite width.
template <class T>
PairOutput<T> halfspace_halfspace(const ShapeCore<T>& A, const ShapeCore<T>& B, const Transform<T>& b_in_a) {
  const Vec3<T> na = A.halfspace_normal, nb = b_in_a.R * B.halfspace_normal;
  // A point on B's boundary plane, in A's frame.
  const Vec3<T> pb = b_in_a.apply(B.halfspace_normal * B.halfspace_offset);
  PairOutput<T> out;
  out.status = Status::converged;
  out.normal = na;
  // Antiparallel when the sine of the angle between the normals is within rounding of a rotated unit vector
  // (1e3 eps; comparing 1 + cos instead would square the angle).
  if (na.dot(nb) < T(0) && na.cross(nb).norm() <= T(1000) * machine_epsilon<T>()) {
    // B = {x : -na.x <= -na.pb}: the gap between the planes is na.pb - offset_a.
    out.distance = na.dot(pb) - A.halfspace_offset - A.radius - B.radius;
    out.witness_b = pb - B.radius * na;
    out.witness_a = out.witness_b - out.distance * na;
  } else {
    out.distance = -std::numeric_limits<T>::infinity();
    out.witness_a = out.witness_b = Vec3<T>::Constant(quiet_nan<T>());
  }
  return out;
}

}  // namespace batchcol::kernels
