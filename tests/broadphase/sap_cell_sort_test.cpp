// sort_cell(): every path (insertion, slabs, radix, the nearly-sorted attempts) leaves the records sorted by x0 and
// loses none, on random, duplicate, equal, clustered, interleaved and float-range keys, for sizes around each path's
// threshold. CellSweep::within() (one SSE comparison per candidate) reports what the scalar test() reports.
#include "broadphase/sap_cell.hpp"

#include "broadphase/pairs.hpp"
#include "broadphase/sap_grid.hpp"

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
    cases.push_back(x);  // few distinct keys: one slab each, nothing left for the insertion pass
    cases.push_back(std::vector<float>(k, 3.0f));  // all equal
    for (std::size_t i = 0; i < k; ++i) x[i] = i % 2 ? FLT_MAX * unit(rng) : -FLT_MAX * unit(rng);
    cases.push_back(x);  // range overflows float: the slab scale is infinite, radix
    for (std::size_t i = 0; i < k; ++i) x[i] = static_cast<float>(k - i);
    cases.push_back(x);  // reversed
    for (std::size_t i = 0; i < k; ++i) x[i] = i < k - 1 ? 1.0f + 1e-6f * unit(rng) : 1e6f;
    cases.push_back(x);  // one outlier: every other key falls into the first slab, the budget fails, radix
    for (std::size_t i = 0; i < k; ++i) x[i] = static_cast<float>(i % 2 ? i : i + k);
    cases.push_back(x);  // two sorted runs interleaved: one descent in two, slabs
    for (std::size_t i = 0; i < k; ++i) x[i] = static_cast<float>(i / 2);
    std::sort(x.begin(), x.end());
    x[k / 2] = -1.0f, x[k - 1] = 0.5f, x[k / 3] = static_cast<float>(k);
    cases.push_back(x);  // sorted but for three far-displaced keys: few descents, the predicted insertion sort
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

// Records sorted by x0 whose grid-axis fields take the values where a 4-wide comparison could differ from four scalar
// ones: +-0, +-inf, +-FLT_MAX, touching intervals, and tombstones.
TEST(SapCellSweep, WithinReportsWhatTheScalarTestReports) {
  std::mt19937 rng(11);
  const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, FLT_MAX, -FLT_MAX, 0.5f, 2.0f};
  const auto pick = [&] { return special[rng() % 8]; };
  const SapGrid grid;  // one cell: every overlapping pair belongs to it
  const FilterSoa filter;
  std::size_t reported = 0;
  for (int round = 0; round < 300; ++round) {
    const std::size_t k = 2 + rng() % 60;
    std::vector<CellRecord> e(k);
    for (std::size_t i = 0; i < k; ++i) {
      float u0 = pick(), u1 = pick(), v0 = pick(), v1 = pick();
      if (u1 < u0) std::swap(u0, u1);
      if (v1 < v0) std::swap(v0, v1);
      e[i] = {static_cast<float>(rng() % 8), 0.0f, u0, u1, v0, v1, static_cast<std::uint32_t>(i)};
      e[i].x1 = e[i].x0 + static_cast<float>(rng() % 4);
      if (rng() % 8 == 0) make_tombstone(e[i]);
    }
    std::sort(e.begin(), e.end(), [](const CellRecord& a, const CellRecord& b) { return a.x0 < b.x0; });
    std::vector<std::uint64_t> got, want;
    CellSweep{grid, 0, 0, filter, got}.within(e.data(), k);
    const CellSweep scalar{grid, 0, 0, filter, want};
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = i + 1; j < k && e[j].x0 <= e[i].x1; ++j) scalar.test(e[i], e[j]);
    ASSERT_EQ(got, want) << "round " << round;
    reported += want.size();
  }
  EXPECT_GT(reported, 1000u);  // the rounds do report pairs, not only rejections
}

}  // namespace
}  // namespace batchcol::broadphase
