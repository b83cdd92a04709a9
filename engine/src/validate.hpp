// Validation at the API boundary: whole-call problems throw InputError, per-pair problems become a status.
#pragma once

#include "batchcol/batch.hpp"

#include <optional>

namespace batchcol::detail {

/// Quaternions whose norm is within this of 1 are normalised; beyond it they are rejected (a typo, not rounding).
constexpr double kQuaternionNormTolerance = 1e-6;

/// Throws InputError when the arrays of `batch` have different lengths.
void validate_batch_layout(const PairBatch& batch);

/// The unit quaternion for `q`, or nothing when q is not finite or not unit within kQuaternionNormTolerance.
std::optional<Eigen::Quaterniond> unit_quaternion(const Eigen::Quaterniond& q);

}  // namespace batchcol::detail
