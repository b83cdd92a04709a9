// Bitwise comparison of whole PairResults, for the determinism tests (thread counts, instruction sets).
#pragma once

#include "batchcol/batchcol.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace batchcol::testing {

/// Same doubles bit for bit (NaN payloads included, unlike ==).
/// (Any allocator: the derivative arrays' storage is line-aligned.)
template <class Allocator>
bool same_bits(const std::vector<double, Allocator>& a, const std::vector<double, Allocator>& b) {
  // memcmp must not see the null data() of empty arrays (the levels that leave them empty), even for 0 bytes.
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

/// Expects every field of `got` bitwise equal to `want`'s; `label` names the comparison in failures.
inline void expect_same_results(const PairResults& want, const PairResults& got, const std::string& label) {
  EXPECT_EQ(want.status, got.status) << label;
  EXPECT_EQ(want.collide, got.collide) << label;
  EXPECT_EQ(want.iterations, got.iterations) << label;
  EXPECT_TRUE(same_bits(want.distance, got.distance)) << label;
  for (auto m : {&PairResults::witness_a, &PairResults::witness_b, &PairResults::normal, &PairResults::direction})
    EXPECT_TRUE(same_bits((want.*m).x, (got.*m).x) && same_bits((want.*m).y, (got.*m).y) &&
                same_bits((want.*m).z, (got.*m).z))
        << label;
}

/// The vector instruction sets this CPU runs (avx2, avx512), to compare each with the scalar one.
inline std::vector<InstructionSet> vector_isas_here() {
  std::vector<InstructionSet> isas;
  for (InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
    try {
      resolve_instruction_set(isa);
      isas.push_back(isa);
    } catch (const InputError&) {
      // not on this CPU
    }
  }
  return isas;
}

/// Expects the status, both distance gradients and the six Jacobians of `got` bitwise equal to `want`'s.
inline void expect_same_derivatives(const DerivativeResults& want, const DerivativeResults& got,
                                    const std::string& label) {
  EXPECT_EQ(want.status, got.status) << label;
  EXPECT_TRUE(same_bits(want.distance_gradient_a.data, got.distance_gradient_a.data)) << label;
  EXPECT_TRUE(same_bits(want.distance_gradient_b.data, got.distance_gradient_b.data)) << label;
  for (auto m : {&DerivativeResults::witness_a_wrt_a, &DerivativeResults::witness_a_wrt_b,
                 &DerivativeResults::witness_b_wrt_a, &DerivativeResults::witness_b_wrt_b,
                 &DerivativeResults::normal_wrt_a, &DerivativeResults::normal_wrt_b})
    EXPECT_TRUE(same_bits((want.*m).data, (got.*m).data)) << label;
}

/// Casts `rays` again in parts of `part` rays (below the ordered cast's 4096-ray threshold, so in input order) and
/// checks every ray's status, hit, object, t and normal bit for bit against `whole`, the cast of the whole batch.
inline ::testing::AssertionResult cast_in_parts_matches(const RaySceneIndex& index, const RayBatch& rays,
                                                        const RayOptions& options, const RayResults& whole,
                                                        std::size_t part = 1000) {
  for (std::size_t begin = 0; begin < rays.size(); begin += part) {
    RayBatch some;
    const std::size_t end = std::min(rays.size(), begin + part);
    for (std::size_t i = begin; i < end; ++i) some.add(rays.origin[i], rays.direction[i], rays.t_max[i]);
    RayResults r;
    index.cast(some, options, r);
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t k = i - begin;
      const double a[4] = {whole.t[i], whole.normal.x[i], whole.normal.y[i], whole.normal.z[i]};
      const double b[4] = {r.t[k], r.normal.x[k], r.normal.y[k], r.normal.z[k]};
      if (whole.status[i] != r.status[k] || whole.hit[i] != r.hit[k] || whole.object[i] != r.object[k] ||
          std::memcmp(a, b, sizeof a) != 0)
        return ::testing::AssertionFailure() << "ray " << i << ": the whole batch's status, hit, object, t or normal "
                                             << "differs from its part's";
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace batchcol::testing
