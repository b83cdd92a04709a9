// PairResults in two steps, so that the executor can fill each tile's slice on the thread that then overwrites
// it (in cache, in parallel) instead of filling the whole batch up front on one thread.
#pragma once

#include "batchcol/batch.hpp"

namespace batchcol::detail {

/// Gives every array n entries; their values are unspecified until fill_defaults() runs on them.
void size_results(PairResults& r, std::size_t n);
/// Entries [begin, end): status invalid_input, collide 0, iterations 0, everything else NaN.
void fill_defaults(PairResults& r, std::size_t begin, std::size_t end);

}  // namespace batchcol::detail
