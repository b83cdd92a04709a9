// Validation at the API boundary: whole-call problems throw InputError, per-pair problems become a status.
#pragma once

#include "batchcol/batch.hpp"

#include <cmath>
#include <optional>

namespace batchcol::detail {

/// Throws InputError when the arrays of `batch` have different lengths.
void validate_batch_layout(const PairBatch& batch);
/// Throws InputError when the arrays of `batch` have different lengths or a non-empty one has a null pointer.
void validate_batch_layout(const PairBatchView& batch);

/// The unit quaternion for `q`, or nothing when q is not finite or not unit within kUnitTolerance.
std::optional<Eigen::Quaterniond> unit_quaternion(const Eigen::Quaterniond& q);

/// The executor's rule on its hot path: q = (w, x, y, z) is accepted when | |q| - 1 | <= kUnitTolerance, with
/// |q| = sqrt(((w w + x x) + y y) + z z) as the SIMD kernels compute it (a NaN or infinite component fails the
/// comparison), and is then divided by |q| in place.
inline bool normalize_unit_quaternion(double q[4]) {
  const double norm = std::sqrt(((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]) + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) return false;
  for (int c = 0; c < 4; ++c) q[c] /= norm;
  return true;
}

}  // namespace batchcol::detail
