// PairResults in two steps, so that the executor writes each entry once: sized without values, then every pair's
// fields written by the kernel that answers it (the SIMD closed forms write NaN / 0 into the computed fields they
// leave; the per-pair path starts each pair from fill_pair_defaults).
#pragma once

#include "batchcol/batch.hpp"

#include <limits>

namespace batchcol::detail {

/// Gives n entries to every array `level` computes and leaves the others empty (see PairResults); the values are
/// unspecified until the kernels or fill_pair_defaults() write them.
void size_results(PairResults& r, std::size_t n, QueryLevel level);
/// Entry i: status invalid_input, collide 0, iterations 0, every sized value array NaN.
inline void fill_pair_defaults(PairResults& r, std::size_t i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.status[i] = Status::invalid_input;
  r.collide[i] = 0;
  if (!r.distance.empty()) r.distance[i] = nan;
  for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal, &r.direction})
    if (!v->x.empty()) v->x[i] = v->y[i] = v->z[i] = nan;
  r.iterations[i] = 0;
}

}  // namespace batchcol::detail
