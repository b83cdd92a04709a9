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
