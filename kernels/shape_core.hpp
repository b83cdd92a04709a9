// The core of a shape as the kernels see it: the geometry GJK iterates on, plus a swept-sphere radius added
// outside the iterations (Montaut et al. 2022, "GJK++", sec. on swept-sphere shapes). A sphere is a point
// inflated by its radius and a capsule a segment inflated by its radius, so their cores are exact polytopes.
#pragma once

#include "batchcol/shapes.hpp"
#include "kernels/math.hpp"

#include <array>

namespace batchcol::kernels {

template <class T> struct ShapeCore {
  ShapeType type = ShapeType::sphere;
  Vec3<T> size = Vec3<T>::Zero();  // box half extents; (r, h, 0) for cylinder/cone; ellipsoid radii; capsule (0, h, 0)
  T radius = T(0);                 // swept-sphere radius: sphere/capsule radius + inflation
  const ConvexHull* hull = nullptr;
  std::array<Vec3<T>, 3> triangle{};
  Vec3<T> halfspace_normal = Vec3<T>::Zero();
  T halfspace_offset = T(0);

  /// True when the core is strictly convex: the plain Nesterov direction is used instead of the normalised one.
  bool strictly_convex() const { return type == ShapeType::ellipsoid; }
  /// A point inside the core (its centre), used to seed the first GJK direction.
  Vec3<T> center() const {
    if (type == ShapeType::convex) return hull->centroid.template cast<T>();
    if (type == ShapeType::triangle) return (triangle[0] + triangle[1] + triangle[2]) / T(3);
    return Vec3<T>::Zero();
  }
};

template <class T> ShapeCore<T> make_core(const Shape& shape) {
  ShapeCore<T> core;
  core.type = shape.type;
  core.radius = T(shape.inflation);
  switch (shape.type) {
    case ShapeType::sphere: core.radius += T(shape.size.x()); break;
    case ShapeType::capsule:
      core.radius += T(shape.size.x());
      core.size = Vec3<T>(T(0), T(shape.size.y()), T(0));
      break;
    case ShapeType::convex: core.hull = shape.hull.get(); break;
    case ShapeType::triangle:
      for (int i = 0; i < 3; ++i) core.triangle[i] = shape.triangle[i].cast<T>();
      break;
    case ShapeType::halfspace:
      core.halfspace_normal = shape.size.cast<T>();
      core.halfspace_offset = T(shape.offset);
      break;
    default: core.size = shape.size.cast<T>(); break;
  }
  return core;
}

}  // namespace batchcol::kernels
