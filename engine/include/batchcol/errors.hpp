// The one exception type of the public API. It is thrown only at the API boundary (shape construction, file
// input, batch submission), never from inside a worker task; per-pair problems are reported as statuses.
#pragma once

#include "batchcol/export.hpp"

#include <stdexcept>
#include <string>

namespace batchcol {

class BATCHCOL_API InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace batchcol
