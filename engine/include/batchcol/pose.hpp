// Rigid poses and small SoA vector arrays shared by batches and results.
// Conventions: metres, right-handed frames, quaternions written [w, x, y, z].
#pragma once

#include "batchcol/export.hpp"
#include "batchcol/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace batchcol {

// kUnitTolerance (how far from unit norm a quaternion may be): batchcol/types.hpp.

/// True when q is finite and | |q| - 1 | <= kUnitTolerance.
BATCHCOL_API bool is_unit_quaternion(const Eigen::Quaterniond& q);
/// The normalised quaternion; throws InputError unless | |q| - 1 | <= kUnitTolerance and q is finite.
BATCHCOL_API Eigen::Quaterniond checked_unit_quaternion(const Eigen::Quaterniond& q);
/// The unit quaternion of a rotation matrix; throws InputError unless R R^T = I and det R = +1 within
/// kUnitTolerance.
BATCHCOL_API Eigen::Quaterniond rotation_from_matrix(const Eigen::Matrix3d& R);

/// A rigid transform x_world = rotation * x_local + translation.
struct Pose {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // Eigen's constructor takes (w, x, y, z)

  static Pose identity() { return {}; }
  static Pose from_translation(const Eigen::Vector3d& t) { return {t, Eigen::Quaterniond::Identity()}; }
  /// Accepts a rotation matrix at the boundary (validated by rotation_from_matrix).
  static Pose from_matrix(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) { return {t, rotation_from_matrix(R)}; }
};

/// Structure-of-arrays storage of 3-vectors: one contiguous array per component.
struct Vec3Array {
  std::vector<double> x, y, z;

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  void resize(std::size_t n, double value = 0.0) { x.resize(n, value); y.resize(n, value); z.resize(n, value); }
  void reserve(std::size_t n) { x.reserve(n); y.reserve(n); z.reserve(n); }
  void push_back(const Eigen::Vector3d& v) { x.push_back(v.x()); y.push_back(v.y()); z.push_back(v.z()); }
  void set(std::size_t i, const Eigen::Vector3d& v) { x[i] = v.x(); y[i] = v.y(); z[i] = v.z(); }
  Eigen::Vector3d operator[](std::size_t i) const { return {x[i], y[i], z[i]}; }
};

/// Structure-of-arrays storage of quaternions [w, x, y, z].
struct QuatArray {
  std::vector<double> w, x, y, z;

  std::size_t size() const { return w.size(); }
  void resize(std::size_t n) { w.resize(n, 1.0); x.resize(n, 0.0); y.resize(n, 0.0); z.resize(n, 0.0); }
  void reserve(std::size_t n) { w.reserve(n); x.reserve(n); y.reserve(n); z.reserve(n); }
  void push_back(const Eigen::Quaterniond& q) { w.push_back(q.w()); x.push_back(q.x()); y.push_back(q.y()); z.push_back(q.z()); }
  void set(std::size_t i, const Eigen::Quaterniond& q) { w[i] = q.w(); x[i] = q.x(); y[i] = q.y(); z[i] = q.z(); }
  Eigen::Quaterniond operator[](std::size_t i) const { return {w[i], x[i], y[i], z[i]}; }
};

/// Read-only view of `count` contiguous values owned by someone else (a NumPy array, a memory-mapped file): the
/// part of std::vector's interface the executor reads, so batches can be viewed instead of copied.
template <class T>
struct ConstSpan {
  const T* ptr = nullptr;
  std::size_t count = 0;

  const T* data() const { return ptr; }
  std::size_t size() const { return count; }
  bool empty() const { return count == 0; }
  const T& operator[](std::size_t i) const { return ptr[i]; }
  static ConstSpan of(const std::vector<T>& v) { return {v.data(), v.size()}; }
};

/// Vec3Array's layout (one contiguous array per component) over memory owned elsewhere.
struct Vec3View {
  ConstSpan<double> x, y, z;

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  Eigen::Vector3d operator[](std::size_t i) const { return {x[i], y[i], z[i]}; }
  static Vec3View of(const Vec3Array& a) {
    return {ConstSpan<double>::of(a.x), ConstSpan<double>::of(a.y), ConstSpan<double>::of(a.z)};
  }
};

/// QuatArray's layout ([w, x, y, z], one contiguous array per component) over memory owned elsewhere.
struct QuatView {
  ConstSpan<double> w, x, y, z;

  std::size_t size() const { return w.size(); }
  Eigen::Quaterniond operator[](std::size_t i) const { return {w[i], x[i], y[i], z[i]}; }
  static QuatView of(const QuatArray& q) {
    return {ConstSpan<double>::of(q.w), ConstSpan<double>::of(q.x), ConstSpan<double>::of(q.y),
            ConstSpan<double>::of(q.z)};
  }
};

}  // namespace batchcol
