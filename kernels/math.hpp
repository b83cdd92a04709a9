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

// Reductions with one fixed association, (a0 b0 + a1 b1) + a2 b2. Eigen's own dot products and 3x3 products
// associate differently for float and double and change with the instruction set it vectorizes for (measured:
// double R * v matched neither order under -mavx2), so the GJK path uses these: the SIMD kernels repeat the same
// operations in the same order and agree with this reference bit for bit.
template <class T> T dot3(const Vec3<T>& a, const Vec3<T>& b) { return (a.x() * b.x() + a.y() * b.y()) + a.z() * b.z(); }
template <class T> T norm2(const Vec3<T>& a) { return dot3(a, a); }
template <class T> T norm3(const Vec3<T>& a) { return std::sqrt(norm2(a)); }
template <class T> Vec3<T> cross3(const Vec3<T>& a, const Vec3<T>& b) {
  return Vec3<T>(a.y() * b.z() - a.z() * b.y(), a.z() * b.x() - a.x() * b.z(), a.x() * b.y() - a.y() * b.x());
}
/// R v, row by row with dot3's association.
template <class T> Vec3<T> mul(const Mat3<T>& R, const Vec3<T>& v) {
  return Vec3<T>((R(0, 0) * v.x() + R(0, 1) * v.y()) + R(0, 2) * v.z(),
                 (R(1, 0) * v.x() + R(1, 1) * v.y()) + R(1, 2) * v.z(),
                 (R(2, 0) * v.x() + R(2, 1) * v.y()) + R(2, 2) * v.z());
}
/// R^T v, column by column with dot3's association.
template <class T> Vec3<T> mul_transposed(const Mat3<T>& R, const Vec3<T>& v) {
  return Vec3<T>((R(0, 0) * v.x() + R(1, 0) * v.y()) + R(2, 0) * v.z(),
                 (R(0, 1) * v.x() + R(1, 1) * v.y()) + R(2, 1) * v.z(),
                 (R(0, 2) * v.x() + R(1, 2) * v.y()) + R(2, 2) * v.z());
}

/// Rotation matrix of the unit quaternion (w, x, y, z), entry by entry in the order the SIMD closed forms use
/// (PairLanes::column in simd/wide_pairs.inl).
template <class T> Mat3<T> rotation_matrix(T w, T x, T y, T z) {
  Mat3<T> R;
  T* m = R.data();  // column-major: R(i, j) = m[i + 3 j]
  m[0] = T(1) - T(2) * (y * y + z * z), m[1] = T(2) * (x * y + w * z), m[2] = T(2) * (x * z - w * y);
  m[3] = T(2) * (x * y - w * z), m[4] = T(1) - T(2) * (x * x + z * z), m[5] = T(2) * (y * z + w * x);
  m[6] = T(2) * (x * z + w * y), m[7] = T(2) * (y * z - w * x), m[8] = T(1) - T(2) * (x * x + y * y);
  return R;
}
/// A^T B, entry (i, j) = column i of A . column j of B with dot3's association.
template <class T> Mat3<T> transposed_product(const Mat3<T>& A, const Mat3<T>& B) {
  Mat3<T> P;
  const T *a = A.data(), *b = B.data();
  T* p = P.data();
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) p[i + 3 * j] = (a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1]) + a[3 * i + 2] * b[3 * j + 2];
  return P;
}

/// A rigid transform x_parent = R x_local + t, in precision T.
template <class T> struct Transform {
  Mat3<T> R = Mat3<T>::Identity();
  Vec3<T> t = Vec3<T>::Zero();

  Vec3<T> apply(const Vec3<T>& p) const { return mul(R, p) + t; }
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
