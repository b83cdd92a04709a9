// sort_cell(): every path (insertion, slabs, radix, the nearly-sorted attempt) leaves the records sorted by x0 and
// loses none, on random, duplicate, equal, clustered and float-range keys, for sizes around each path's threshold.
#include "broadphase/sap_cell.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace batchcol::broadphase {
namespace {

std::vector<CellRecord> records(const std::vector<float>& x0) {
  std::vector<CellRecord> r(x0.size());
  for (std::size_t i = 0; i < x0.size(); ++i)
    r[i] = {x0[i], x0[i] + 1.0f, 0.0f, 1.0f, 0.0f, 1.0f, static_cast<std::uint32_t>(i)};
  return r;
}

// Sorted by x0, and the same multiset of (x0, id) as the input (each record kept whole: x1 = x0 + 1 still holds).
void expect_sorted_permutation(const std::vector<CellRecord>& in, const std::vector<CellRecord>& out) {
  ASSERT_EQ(in.size(), out.size());
  for (std::size_t i = 1; i < out.size(); ++i) ASSERT_LE(out[i - 1].x0, out[i].x0) << "at " << i;
  std::vector<std::uint32_t> seen(in.size(), 0);
  for (const CellRecord& r : out) {
    ASSERT_LT(r.id, in.size());
    ++seen[r.id];
    EXPECT_EQ(r.x0, in[r.id].x0);
    EXPECT_EQ(r.x1, in[r.id].x1);
  }
  for (std::uint32_t c : seen) ASSERT_EQ(c, 1u);
}

TEST(SapCellSort, EveryPathSortsAndKeepsEveryRecord) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  SortScratch scratch;
  // Around the insertion (48), slab (4096) thresholds, and beyond.
  for (const std::size_t k : {2u, 47u, 48u, 49u, 250u, 1000u, 4095u, 4096u, 4097u, 9000u}) {
    std::vector<std::vector<float>> cases;
    std::vector<float> x(k);
    for (float& v : x) v = unit(rng);
    cases.push_back(x);  // random
    for (float& v : x) v = static_cast<float>(rng() % 5);
    cases.push_back(x);  // few distinct keys: full slabs, the budget fails, radix finishes
    cases.push_back(std::vector<float>(k, 3.0f));  // all equal
    for (std::size_t i = 0; i < k; ++i) x[i] = i % 2 ? FLT_MAX * unit(rng) : -FLT_MAX * unit(rng);
    cases.push_back(x);  // range overflows float: the slab scale is infinite, radix
    for (std::size_t i = 0; i < k; ++i) x[i] = static_cast<float>(k - i);
    cases.push_back(x);  // reversed
    for (std::size_t i = 0; i < k; ++i) x[i] = i < k - 1 ? 1.0f + 1e-6f * unit(rng) : 1e6f;
    cases.push_back(x);  // one outlier: every other key falls into the first slab
    for (std::size_t c = 0; c < cases.size(); ++c)
      for (const bool nearly : {false, true}) {
        SCOPED_TRACE("k = " + std::to_string(k) + ", case " + std::to_string(c) + (nearly ? ", nearly" : ""));
        const std::vector<CellRecord> in = records(cases[c]);
        std::vector<CellRecord> out = in;
        sort_cell(out.data(), out.size(), nearly, scratch);
        expect_sorted_permutation(in, out);
      }
  }
}

}  // namespace
}  // namespace batchcol::broadphase
