// Validation at the API boundary: whole-call problems throw InputError, per-pair problems become a status.
#pragma once

#include "batchcol/batch.hpp"

#include <optional>

namespace batchcol::detail {

/// Throws InputError when the arrays of `batch` have different lengths.
void validate_batch_layout(const PairBatch& batch);

/// The unit quaternion for `q`, or nothing when q is not finite or not unit within kUnitTolerance.
std::optional<Eigen::Quaterniond> unit_quaternion(const Eigen::Quaterniond& q);

}  // namespace batchcol::detail
