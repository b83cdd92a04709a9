// Small math vocabulary shared by the scalar reference kernels.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace batchcol::kernels {

template <class T> using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T> using Mat3 = Eigen::Matrix<T, 3, 3>;

template <class T> constexpr T machine_epsilon() { return std::numeric_limits<T>::epsilon(); }
template <class T> T quiet_nan() { return std::numeric_limits<T>::quiet_NaN(); }

/// A rigid transform x_parent = R x_local + t, in precision T.
template <class T> struct Transform {
  Mat3<T> R = Mat3<T>::Identity();
  Vec3<T> t = Vec3<T>::Zero();

  Vec3<T> apply(const Vec3<T>& p) const { return R * p + t; }
};

/// Any unit vector orthogonal to `v` (v need not be normalised, must be non-zero).
template <class T> Vec3<T> any_orthogonal(const Vec3<T>& v) {
  // Cross with the coordinate axis least aligned with v: the result is never close to zero.
  const Vec3<T> a = v.cwiseAbs();
  Vec3<T> axis = Vec3<T>::Zero();
  if (a.x() <= a.y() && a.x() <= a.z()) axis.x() = T(1);
  else if (a.y() <= a.z()) axis.y() = T(1);
  else axis.z() = T(1);
  return v.cross(axis).normalized();
}

}  // namespace batchcol::kernels
