// PairResults in two steps, so that the executor writes each entry once: sized without values, then every pair's
// fields written by the kernel that answers it (the SIMD closed forms write NaN / 0 into the fields they do not
// compute; the per-pair path starts each pair from fill_pair_defaults).
#pragma once

#include "batchcol/batch.hpp"

#include <limits>

namespace batchcol::detail {

/// Gives every array n entries; their values are unspecified until fill_defaults() runs on them.
void size_results(PairResults& r, std::size_t n);
/// Entry i: status invalid_input, collide 0, iterations 0, everything else NaN.
inline void fill_pair_defaults(PairResults& r, std::size_t i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.status[i] = Status::invalid_input;
  r.collide[i] = 0;
  r.distance[i] = nan;
  for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal, &r.direction}) v->x[i] = v->y[i] = v->z[i] = nan;
  r.iterations[i] = 0;
}

}  // namespace batchcol::detail
