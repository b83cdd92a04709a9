#include "batchcol/errors.hpp"
#include "batchcol/pose.hpp"
#include "validate.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace batchcol {

// Every quaternion check of the library goes through detail::normalize_unit_quaternion (validate.hpp), the rule of
// the executor's hot path and the SIMD kernels: near the kUnitTolerance boundary the last bit of the norm decides,
// so one summation order everywhere (not Eigen's norm() here and a fixed order there) keeps the same quaternion
// valid or invalid whatever the shape types, the kernel or the entry point.
bool is_unit_quaternion(const Eigen::Quaterniond& q) {
  double c[4] = {q.w(), q.x(), q.y(), q.z()};
  return detail::normalize_unit_quaternion(c);
}

Eigen::Quaterniond checked_unit_quaternion(const Eigen::Quaterniond& q) {
  if (!q.coeffs().allFinite()) throw InputError("the quaternion has a non-finite component");
  if (!is_unit_quaternion(q)) {
    const double norm = q.coeffs().stableNorm();  // q.norm() overflows for components beyond 1e154
    std::ostringstream msg;
    // 10 digits: a norm of 1.0000011 must not print as "1" (6 digits, the default).
    msg << "the quaternion [w, x, y, z] must have norm 1 (within " << kUnitTolerance << "), its norm is "
        << std::setprecision(10) << norm;
    throw InputError(msg.str());
  }
  return *detail::unit_quaternion(q);
}

Eigen::Quaterniond rotation_from_matrix(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) throw InputError("the rotation matrix has a non-finite entry");
  const double orthogonality = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  if (!(orthogonality <= kUnitTolerance) || !(std::abs(det - 1.0) <= kUnitTolerance)) {
    std::ostringstream msg;
    msg << "not a rotation matrix (needs R R^T = I and det R = +1 within " << kUnitTolerance
        << std::setprecision(10) << "; max |R R^T - I| = " << orthogonality << ", det = " << det << ")";
    throw InputError(msg.str());
  }
  return Eigen::Quaterniond(R).normalized();
}

}  // namespace batchcol
