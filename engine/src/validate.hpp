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

/// Throws InputError when the table's shapes are beyond what `options.precision` can answer (float32: sizes and
/// bounding radii within [kMinLengthFloat, kMaxLengthFloat]; double is guaranteed by the shape factories).
void validate_shapes_for(const ShapeTable& shapes, const QueryOptions& options);

/// The per-pair translation limit: |x| + |y| + |z| <= kMaxLength (NaN and infinite components fail), summed in
/// this order as the SIMD kernels do (kernels/simd/wide_pairs.inl, load_pose).
inline bool translation_in_range(const Eigen::Vector3d& t) {
  return (std::abs(t.x()) + std::abs(t.y())) + std::abs(t.z()) <= kMaxLength;
}

/// Precision::float32: pairs [begin, end) whose relative translation exceeds kMaxLengthFloat (|x| + |y| + |z| of
/// translation_b - translation_a) become invalid_input, whatever the float kernels computed for them.
void refuse_beyond_float_limits(const PairBatchView& batch, std::size_t begin, std::size_t end, PairResults& results);

/// The unit quaternion for `q` (normalize_unit_quaternion's rule and division), or nothing when q is not finite or
/// not unit within kUnitTolerance.
std::optional<Eigen::Quaterniond> unit_quaternion(const Eigen::Quaterniond& q);

/// THE quaternion rule of the library (is_unit_quaternion, checked_unit_quaternion, unit_quaternion, the executor's
/// hot path, scenes and rays all call it): q = (w, x, y, z) is accepted when | |q| - 1 | <= kUnitTolerance, with
/// |q| = sqrt(((w w + x x) + y y) + z z) as the SIMD kernels compute it (a NaN or infinite component fails the
/// comparison), and is then divided by |q| in place.
inline bool normalize_unit_quaternion(double q[4]) {
  const double norm = std::sqrt(((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]) + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) return false;
  for (int c = 0; c < 4; ++c) q[c] /= norm;
  return true;
}

}  // namespace batchcol::detail
