// The core of a shape as the kernels see it: the geometry GJK iterates on, plus a swept-sphere radius added
// outside the iterations (Montaut et al. 2022, "GJK++", sec. on swept-sphere shapes). A sphere is a point
// inflated by its radius and a capsule a segment inflated by its radius, so their cores are exact polytopes.
// Built from the plain ShapeView the engine hands over (batchcol/types.hpp): the kernels never see Shape.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/math.hpp"

#include <array>

namespace batchcol::kernels {

/// Vertex i, face normal f, of a hull view, as an Eigen vector over the view's doubles (no copy).
inline Eigen::Map<const Eigen::Vector3d> hull_vertex(const HullView& h, std::uint32_t i) {
  return Eigen::Map<const Eigen::Vector3d>(h.vertices + 3 * std::size_t(i));
}
inline Eigen::Map<const Eigen::Vector3d> hull_face_normal(const HullView& h, std::uint32_t f) {
  return Eigen::Map<const Eigen::Vector3d>(h.face_normals + 3 * std::size_t(f));
}
/// The hull's centroid in precision T (each coordinate rounded once, as a cast of the double vector).
template <class T> Vec3<T> hull_centroid(const HullView& h) {
  return Vec3<T>(T(h.centroid[0]), T(h.centroid[1]), T(h.centroid[2]));
}

template <class T> struct ShapeCore {
  ShapeType type = ShapeType::sphere;
  Vec3<T> size = Vec3<T>::Zero();  // box half extents; (r, h, 0) for cylinder/cone; ellipsoid radii; capsule (0, h, 0)
  T radius = T(0);                 // swept-sphere radius: sphere/capsule radius + inflation
  const HullView* hull = nullptr;
  std::array<Vec3<T>, 3> triangle{};
  Vec3<T> halfspace_normal = Vec3<T>::Zero();
  T halfspace_offset = T(0);

  /// True when the core is strictly convex: the plain Nesterov direction is used instead of the normalised one.
  bool strictly_convex() const { return type == ShapeType::ellipsoid; }
  /// A point inside the core (its centre), used to seed the first GJK direction.
  Vec3<T> center() const {
    if (type == ShapeType::convex) return hull_centroid<T>(*hull);
    if (type == ShapeType::triangle) return (triangle[0] + triangle[1] + triangle[2]) / T(3);
    return Vec3<T>::Zero();
  }
};

/// The core of `shape`; a convex core points to shape.hull (the HullView, which must outlive the core).
template <class T> ShapeCore<T> make_core(const ShapeView& shape) {
  ShapeCore<T> core;
  core.type = shape.type;
  core.radius = T(shape.inflation);
  const Vec3<T> size(T(shape.size[0]), T(shape.size[1]), T(shape.size[2]));
  switch (shape.type) {
    case ShapeType::sphere: core.radius += size.x(); break;
    case ShapeType::capsule:
      core.radius += size.x();
      core.size = Vec3<T>(T(0), size.y(), T(0));
      break;
    case ShapeType::convex: core.hull = shape.hull; break;
    case ShapeType::triangle:
      for (int i = 0; i < 3; ++i)
        core.triangle[i] = Vec3<T>(T(shape.triangle[i][0]), T(shape.triangle[i][1]), T(shape.triangle[i][2]));
      break;
    case ShapeType::halfspace:
      core.halfspace_normal = size;
      core.halfspace_offset = T(shape.offset);
      break;
    default: core.size = size; break;
  }
  return core;
}

}  // namespace batchcol::kernels
