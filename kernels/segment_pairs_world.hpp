// Sphere and capsule pairs straight from their world poses: both cores are segments (a sphere's has zero length),
// so the answer is segments_with_radii() (closed_forms.hpp) on two world segments. Skipping the
// relative frame, the shape cores and the GJK setup makes these pairs ~5x cheaper than the generic path; the
// arithmetic is double whatever the requested precision (as cheap here, and at least as accurate).
#pragma once

#include "kernels/closed_forms.hpp"

namespace batchcol::kernels {

struct WorldSegment {
  Vec3<double> p0, p1;  // core segment (p0 == p1 for a sphere)
  double radius = 0;    // sphere / capsule radius + inflation
};

inline bool is_segment_shape(ShapeType t) { return t == ShapeType::sphere || t == ShapeType::capsule; }

/// The core of a sphere or capsule under a unit quaternion q and translation t: the capsule's local z axis is the
/// third column of q's rotation matrix.
inline WorldSegment world_segment(const ShapeView& s, const Eigen::Quaterniond& q, const Vec3<double>& t) {
  WorldSegment w;
  w.radius = s.size[0] + s.inflation;
  const double h = s.type == ShapeType::capsule ? s.size[1] : 0.0;
  const Vec3<double> axis(2 * (q.x() * q.z() + q.w() * q.y()), 2 * (q.y() * q.z() - q.w() * q.x()),
                          1 - 2 * (q.x() * q.x() + q.y() * q.y()));
  w.p0 = t - h * axis;
  w.p1 = t + h * axis;
  return w;
}

}  // namespace batchcol::kernels
