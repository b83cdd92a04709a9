// Penetration of a point core (a sphere) whose centre lies inside a cylinder or cone core: the depth is the
// distance from the point to the core's boundary, in closed form. EPA converges slowly here (issue #16, item 10:
// it ended max_iterations at every tolerance from 1e-12 to 1e-6 with depth errors of ~1e-5 x the cone's size): the
// Minkowski difference is the curved core itself, whose boundary EPA approximates by ever more facets.
//
// A cylinder is the intersection of a slab |z| <= h and an infinite cylinder rho <= R; a cone (apex (0, 0, h), base
// disc of radius R at z = -h) of the half-space z >= -h and an infinite cone. For a point inside an intersection of
// convex sets the distance to its boundary is the smallest distance to the sets' boundaries (the complement of an
// intersection is the union of the complements). For the infinite cone, the closest boundary point of an interior
// point lies in the point's own half-plane through the axis, at the foot of the perpendicular on the side line,
// which falls between the apex and infinity (t > 0 below the apex).
#pragma once

#include "kernels/shape_core.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::kernels {

template <class T> struct PointDepth {
  T depth = T(0);                     // distance from the point to the core's boundary (>= 0)
  Vec3<T> normal = Vec3<T>::UnitX();  // unit outward normal of the core at the closest boundary point
};

/// The depth of `p` (core frame) inside a cylinder or cone core; false when the core is another type or `p` is not
/// strictly inside (then EPA answers).
template <class T> bool point_depth_in_core(const ShapeCore<T>& core, const Vec3<T>& p, PointDepth<T>& out) {
  if (core.type != ShapeType::cylinder && core.type != ShapeType::cone) return false;
  const T R = core.size.x(), h = core.size.y();
  const T rho = std::sqrt(p.x() * p.x() + p.y() * p.y());
  // The radial direction of p (any, here +x, on the axis: every direction is then as close).
  const Vec3<T> radial = rho > T(0) ? Vec3<T>(p.x() / rho, p.y() / rho, T(0)) : Vec3<T>::UnitX();
  T side;
  Vec3<T> side_normal;
  T depth_bottom = p.z() + h, depth_top;
  if (core.type == ShapeType::cylinder) {
    side = R - rho;
    side_normal = radial;
    depth_top = h - p.z();
  } else {
    // Side line from the apex (0, h) to the rim (R, -h) in the (rho, z) half-plane; outward normal (2h, R) / L.
    const T L = std::sqrt(R * R + T(4) * h * h);
    side = (R * (h - p.z()) - T(2) * h * rho) / L;
    side_normal = Vec3<T>(T(2) * h * radial.x() / L, T(2) * h * radial.y() / L, R / L);
    depth_top = h - p.z();  // p below the apex (with side >= 0 this holds; checked for safety)
  }
  if (!(side > T(0) && depth_bottom > T(0) && depth_top > T(0))) return false;
  out.depth = side;
  out.normal = side_normal;
  if (depth_bottom < out.depth) out.depth = depth_bottom, out.normal = Vec3<T>(T(0), T(0), T(-1));
  if (core.type == ShapeType::cylinder && depth_top < out.depth) out.depth = depth_top, out.normal = Vec3<T>::UnitZ();
  return true;
}

}  // namespace batchcol::kernels

namespace batchcol::kernels {

/// The distance from `p` (core frame) outside a cylinder or cone core to the core, with the closest point and the
/// unit normal there pointing to p (an outward normal of the core at p when p is on the boundary); false when the
/// core is another type or p is strictly inside (point_depth_in_core answers then) or not finite. Used where GJK
/// stalls with cores a hair apart (issue #16, item 10): its x is then exact to rounding but its direction, the
/// difference of nearly equal support points, is off by ~eps scale / |x|, and so is its certificate.
/// In p's half-plane through the axis, (rho, z), the core's profile is the rectangle [0, R] x [-h, h] or the
/// triangle (0, -h), (R, -h), (0, h); the closest point is on its bottom, top or side edge. On an edge's interior
/// the distance and normal come from the edge's line (well conditioned); at a corner from the 2D difference.
template <class T> struct PointDistance {
  T distance = T(0);
  Vec3<T> closest = Vec3<T>::Zero();
  Vec3<T> normal = Vec3<T>::UnitX();
};

template <class T> bool point_distance_to_core(const ShapeCore<T>& core, const Vec3<T>& p, PointDistance<T>& out) {
  if (core.type != ShapeType::cylinder && core.type != ShapeType::cone) return false;
  const T R = core.size.x(), h = core.size.y();
  const T rho = std::sqrt(p.x() * p.x() + p.y() * p.y()), z = p.z();
  const Vec3<T> radial = rho > T(0) ? Vec3<T>(p.x() / rho, p.y() / rho, T(0)) : Vec3<T>::UnitX();
  T c_rho, c_z;       // closest point of the profile
  T dist;             // from the edge's line where the foot is inside the edge
  T n_rho, n_z;       // unit normal in the half-plane
  if (core.type == ShapeType::cylinder) {
    if (rho < R && std::abs(z) < h) return false;
    c_rho = std::min(rho, R);
    c_z = std::clamp(z, -h, h);
    if (rho <= R) dist = std::abs(z) - h, n_rho = T(0), n_z = z > T(0) ? T(1) : T(-1);  // a cap
    else if (std::abs(z) <= h) dist = rho - R, n_rho = T(1), n_z = T(0);                // the side
    else dist = T(-1);                                                                    // a rim
  } else {
    const T L = std::sqrt(R * R + T(4) * h * h);
    const T side = (T(2) * h * rho - R * (h - z)) / L;  // signed distance to the side's line (outward > 0)
    if (z > -h && side < T(0)) return false;
    // The foot on the side line, as a fraction t of the way from the rim (R, -h) to the apex (0, h).
    const T t = ((rho - R) * (-R) + (z + h) * (T(2) * h)) / (L * L);
    if (z <= -h && rho <= R) {
      c_rho = rho, c_z = -h, dist = -h - z, n_rho = T(0), n_z = T(-1);  // the base
    } else if (side >= T(0) && t > T(0) && t < T(1)) {
      c_rho = R * (T(1) - t), c_z = -h + T(2) * h * t, dist = side, n_rho = T(2) * h / L, n_z = R / L;
    } else {
      c_rho = t >= T(1) ? T(0) : R, c_z = t >= T(1) ? h : -h, dist = T(-1);  // the apex or the rim
    }
  }
  if (dist < T(0)) {  // a corner: the 2D difference
    const T dr = rho - c_rho, dz = z - c_z;
    dist = std::sqrt(dr * dr + dz * dz);
    n_rho = dr / dist, n_z = dz / dist;
    // On the corner itself: a normal of its normal cone (radial at a rim, the axis at the apex).
    if (!(dist > T(0))) n_rho = c_rho > T(0) ? T(1) : T(0), n_z = c_rho > T(0) ? T(0) : T(1);
  }
  if (!(dist >= T(0))) return false;
  out.distance = dist;
  out.closest = c_rho * radial + Vec3<T>(T(0), T(0), c_z);
  out.normal = n_rho * radial + Vec3<T>(T(0), T(0), n_z);
  return true;
}

}  // namespace batchcol::kernels
