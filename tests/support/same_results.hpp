// Bitwise comparison of whole PairResults, for the determinism tests (thread counts, instruction sets).
#pragma once

#include "batchcol/batchcol.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace batchcol::testing {

/// Same doubles bit for bit (NaN payloads included, unlike ==).
inline bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
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

}  // namespace batchcol::testing
