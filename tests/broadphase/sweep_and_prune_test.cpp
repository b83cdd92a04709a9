// The sweep-and-prune equals the brute-force reference exactly (inclusive touching, filters) on uniform, clustered
// and degenerate scenes, for any thread count, in rebuild and incremental mode.
#include "broadphase/sap_scenes.hpp"

#include "broadphase/brute_force.hpp"
#include "broadphase/sweep_and_prune.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <sstream>

namespace batchcol::broadphase {
namespace {

using namespace testing;

std::string describe_difference(const std::vector<CandidatePair>& got, const std::vector<CandidatePair>& want) {
  std::ostringstream s;
  s << got.size() << " pairs vs " << want.size() << " expected";
  for (std::size_t k = 0; k < std::min(got.size(), want.size()); ++k)
    if (got[k] != want[k]) {
      s << "; first difference at " << k << ": (" << got[k].a << "," << got[k].b << ") vs (" << want[k].a << ","
        << want[k].b << ")";
      break;
    }
  return s.str();
}

std::vector<CandidatePair> sap_pairs(const AabbSoa& boxes, const FilterSoa& filter = {}) {
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(boxes, filter, pairs);
  return pairs;
}

void expect_equals_brute_force(const AabbSoa& boxes, const FilterSoa& filter = {}) {
  const auto want = brute_force_pairs(boxes, filter);
  const auto got = sap_pairs(boxes, filter);
  EXPECT_TRUE(got == want) << describe_difference(got, want);
}

TEST(SweepAndPrune, EqualsBruteForceOnUniformScenes) {
  Rng rng(1);
  for (std::size_t n : {0, 1, 2, 3, 17, 100, 1000, 6000})
    for (double overlaps : {0.4, 3.0}) {
      SCOPED_TRACE(::testing::Message() << "n=" << n << " overlaps=" << overlaps);
      expect_equals_brute_force(to_soa(uniform_boxes(rng, n, 1.0, half_size_for(n, overlaps))));
    }
}

TEST(SweepAndPrune, EqualsBruteForceOnClusteredScenes) {
  Rng rng(2);
  for (int clusters : {1, 3, 20}) expect_equals_brute_force(to_soa(clustered_boxes(rng, 4000, clusters)));
}

TEST(SweepAndPrune, EqualsBruteForceWithNegativeAndSignedZeroCoordinates) {
  Rng rng(3);
  expect_equals_brute_force(to_soa(uniform_boxes(rng, 3000, 10.0, 0.2, -20.0)));  // all negative
  expect_equals_brute_force(to_soa(uniform_boxes(rng, 3000, 2.0, 0.05, -1.0)));   // straddling zero
  // Boxes touching exactly at -0 / +0 on every axis: the keys of -0 and +0 must be equal.
  AabbSoa s;
  s.resize(4);
  const float m0 = -0.0f;
  for (auto* v : {&s.min_x, &s.min_y, &s.min_z}) *v = {-1.0f, 0.0f, m0, 0.5f};
  for (auto* v : {&s.max_x, &s.max_y, &s.max_z}) *v = {m0, 1.0f, 0.0f, 2.0f};
  const auto pairs = sap_pairs(s);
  EXPECT_EQ(pairs, (std::vector<CandidatePair>{{0, 1}, {0, 2}, {1, 2}, {1, 3}}));
  expect_equals_brute_force(s);
}

TEST(SweepAndPrune, DegenerateScenes) {
  Rng rng(4);
  const Eigen::Vector3d h(0.1, 0.1, 0.1);
  {
    SCOPED_TRACE("all objects at one point");
    expect_equals_brute_force(to_soa(std::vector<Aabb>(300, box_at({1, -2, 3}, h))));
    EXPECT_EQ(sap_pairs(to_soa(std::vector<Aabb>(300, box_at({1, -2, 3}, h)))).size(), 300u * 299u / 2u);
  }
  {
    SCOPED_TRACE("all on a line along x, and along a diagonal");
    std::vector<Aabb> line, diagonal;
    for (int i = 0; i < 2000; ++i) {
      line.push_back(box_at({0.15 * i, 0, 0}, h));
      diagonal.push_back(box_at(Eigen::Vector3d::Constant(0.11 * i), h));
    }
    expect_equals_brute_force(to_soa(line));
    expect_equals_brute_force(to_soa(diagonal));
  }
  {
    SCOPED_TRACE("all the same size on a lattice, faces exactly shared (inclusive touching)");
    std::vector<Aabb> lattice;
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j)
        for (int k = 0; k < 12; ++k)
          lattice.push_back({Eigen::Vector3d(i, j, k) * 0.5, Eigen::Vector3d(i + 1, j + 1, k + 1) * 0.5});
    const AabbSoa s = to_soa(lattice);
    expect_equals_brute_force(s);
    // Every pair of lattice cells at Chebyshev distance 1 touches: 12^3 cells, (2 * 12 - 1)^3 - 12^3 ordered... count
    // directly: pairs of indices differing by at most 1 per axis.
    std::size_t expected = 0;
    const std::size_t per_axis = 12 + 2 * 11;  // pairs (i, i') with |i - i'| <= 1, ordered, i.e. 12 + 2 * 11
    expected = (per_axis * per_axis * per_axis - 12 * 12 * 12) / 2;
    EXPECT_EQ(sap_pairs(s).size(), expected);
  }
  {
    SCOPED_TRACE("huge and tiny together");
    auto b = uniform_boxes(rng, 3000, 100.0, 0.01);
    for (int k = 0; k < 40; ++k)
      b.push_back(box_at({uniform(rng, 0, 100), uniform(rng, 0, 100), uniform(rng, 0, 100)},
                         uniform3(rng, 5, 60)));
    b.push_back(box_at({50, 50, 50}, Eigen::Vector3d::Constant(1e30)));  // covers everything
    expect_equals_brute_force(to_soa(b));
  }
  {
    SCOPED_TRACE("zero-size boxes (points), some coincident, some on other boxes' faces");
    std::vector<Aabb> b;
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector3d p(0.25 * (rng() % 8), 0.25 * (rng() % 8), 0.25 * (rng() % 8));
      b.push_back({p, p});
    }
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d p(0.25 * (rng() % 8), 0.25 * (rng() % 8), 0.25 * (rng() % 8));
      b.push_back({p, p + Eigen::Vector3d::Constant(0.25)});
    }
    expect_equals_brute_force(to_soa(b));
  }
  {
    // Above 2048 objects the grid statistics come from a sample (sap_grid.cpp): degenerate inputs there too.
    SCOPED_TRACE("over 2048 objects: all on a line, all at one point, every 4th box 200x larger (periodic input)");
    std::vector<Aabb> line, point, periodic;
    for (int i = 0; i < 5000; ++i) {
      line.push_back(box_at({0.15 * i, 0, 0}, h));
      point.push_back(box_at({1, 2, 3}, h));
      const Eigen::Vector3d c = uniform3(rng, 0, 100);
      periodic.push_back(box_at(c, Eigen::Vector3d::Constant(i % 4 == 0 ? 2.0 : 0.01)));
    }
    expect_equals_brute_force(to_soa(line));
    EXPECT_EQ(sap_pairs(to_soa(point)).size(), 5000u * 4999u / 2u);
    expect_equals_brute_force(to_soa(periodic));
  }
  {
    SCOPED_TRACE("coordinates near the float range");
    std::vector<Aabb> b;
    for (int i = 0; i < 200; ++i) {
      const double x = (i % 2 ? 1 : -1) * 3.0e38 * uniform(rng, 0.5, 1.0);
      b.push_back({Eigen::Vector3d(x, x, -x), Eigen::Vector3d(x, x, -x) + Eigen::Vector3d::Constant(1e37)});
    }
    expect_equals_brute_force(to_soa(b));
  }
}

TEST(SweepAndPrune, MarginInflatesBoxes) {
  const std::vector<Aabb> b = {box_at({0, 0, 0}, {1, 1, 1}), box_at({2.5, 0, 0}, {1, 1, 1})};
  EXPECT_TRUE(sap_pairs(to_soa(b, 0.2)).empty());
  EXPECT_EQ(sap_pairs(to_soa(b, 0.25)), (std::vector<CandidatePair>{{0, 1}}));  // touching after the margin
}

TEST(SweepAndPrune, FiltersAndBodyExclusionEqualBruteForce) {
  Rng rng(5);
  for (std::size_t n : {500, 5000}) {
    const AabbSoa s = to_soa(clustered_boxes(rng, n, 4));
    FilterSoa f = random_filter(rng, n);
    expect_equals_brute_force(s, f);
    f.group.clear(), f.mask.clear();
    expect_equals_brute_force(s, f);  // bodies only
    f = random_filter(rng, n);
    f.body.clear();
    expect_equals_brute_force(s, f);  // groups only
  }
}

TEST(SweepAndPrune, FilterRules) {
  // Five boxes all overlapping at the origin.
  const AabbSoa s = to_soa(std::vector<Aabb>(5, box_at({0, 0, 0}, {1, 1, 1})));
  FilterSoa f;
  f.group = {1, 1, 2, 2, 1};
  f.mask = {~0u, ~0u, 1, ~0u, 2};  // 2 only accepts group 1; 4 only accepts group 2
  f.body = {7, 7, -1, -1, 3};      // 0 and 1 are one body; -1 means no body
  const std::vector<CandidatePair> want = {{0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 4}, {3, 4}};  // not 2-3, 0-4, 1-4, 0-1
  EXPECT_EQ(sap_pairs(s, f), want);
  EXPECT_EQ(brute_force_pairs(s, f), want);
}

// Scratch that grew with whichever thread happened to sort the largest cell made warm frames allocate at random
// (review of the slab sort); the scratch is now sized from the cells before the parallel sort.
TEST(SweepAndPrune, WarmRebuildsAndUpdatesAllocateNothing) {
  Rng rng(9);
  // Random order (slab sorts) plus a tight cluster that fills one cell past the slab sort's size (radix sort): which
  // worker sorts the big cell varies from frame to frame.
  std::vector<Aabb> a = uniform_boxes(rng, 20000, 1.0, half_size_for(20000, 0.4));
  for (int i = 0; i < 6000; ++i)  // 1e-6 apart on a diagonal 6e-3 long (cells are ~0.03 wide), 2e-7 wide: no pairs
    a.push_back(box_at(Eigen::Vector3d::Constant(0.5 + 1e-6 * ((i * 7919) % 6000)), Eigen::Vector3d::Constant(1e-7)));
  std::vector<Aabb> b = a;
  for (Aabb& box : b) box.min.x() += 1e-4, box.max.x() += 1e-4;
  const AabbSoa sa = to_soa(a), sb = to_soa(b);
  tbb::task_arena(2).execute([&] {
    SweepAndPrune sap;
    std::vector<CandidatePair> pairs;
    for (int k = 0; k < 2; ++k) {  // warm-up: both frames seen by rebuild() and update()
      sap.rebuild(k % 2 ? sb : sa, {}, pairs);
      sap.update(k % 2 ? sa : sb, {}, pairs);
    }
    const std::size_t bytes = sap.memory_bytes();
    for (int k = 0; k < 300; ++k) {  // the old per-thread scratch grew within ~70 frames in half the runs
      sap.rebuild(k % 2 ? sb : sa, {}, pairs);
      ASSERT_EQ(sap.memory_bytes(), bytes) << "rebuild " << k;
      sap.update(k % 2 ? sa : sb, {}, pairs);
      ASSERT_EQ(sap.memory_bytes(), bytes) << "update " << k;
    }
    EXPECT_GT(pairs.size(), 1000u);
    EXPECT_GT(sap.stats().max_cell, 4096u);  // the cluster's cell is past the slab sort: radix
  });
}

TEST(SweepAndPrune, IdenticalForOneAndTwoThreads) {
  Rng rng(6);
  std::vector<AabbSoa> scenes = {to_soa(uniform_boxes(rng, 200000, 1.0, half_size_for(200000, 0.4))),
                                 to_soa(clustered_boxes(rng, 50000, 5)),
                                 to_soa(std::vector<Aabb>(2000, box_at({0, 0, 0}, {1, 1, 1})))};
  for (const AabbSoa& s : scenes) {
    const FilterSoa f = random_filter(rng, s.size());
    std::vector<CandidatePair> one, two, one_inc, two_inc;
    SapStats stats_one, stats_two;
    tbb::task_arena(1).execute([&] {
      SweepAndPrune sap;
      sap.rebuild(s, f, one);
      stats_one = sap.stats();
      sap.update(s, f, one_inc);
    });
    tbb::task_arena(2).execute([&] {
      SweepAndPrune sap;
      sap.rebuild(s, f, two);
      stats_two = sap.stats();
      sap.update(s, f, two_inc);
    });
    EXPECT_FALSE(one.empty());
    EXPECT_TRUE(one == two) << describe_difference(two, one);
    EXPECT_TRUE(one == one_inc);
    EXPECT_TRUE(one == two_inc);
    EXPECT_EQ(stats_one.entries, stats_two.entries);
    EXPECT_EQ(stats_one.cells_u, stats_two.cells_u);
    EXPECT_EQ(stats_one.axis, stats_two.axis);
  }
}

TEST(SweepAndPrune, SweepAxisIsTheAxisOfLargestVariance) {
  Rng rng(7);
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<Aabb> b;
    for (int i = 0; i < 1000; ++i) {
      Eigen::Vector3d c = uniform3(rng, 0, 1);
      c[axis] *= 10;
      b.push_back(box_at(c, Eigen::Vector3d::Constant(0.01)));
    }
    SweepAndPrune sap;
    std::vector<CandidatePair> pairs;
    sap.rebuild(to_soa(b), {}, pairs);
    EXPECT_EQ(sap.stats().axis, axis);
  }
}

TEST(SweepAndPrune, IncrementalUpdatesEqualRebuildAfterSmallMotions) {
  Rng rng(8);
  const std::size_t n = 20000;
  const double h = half_size_for(n, 0.4);
  std::vector<Aabb> b = uniform_boxes(rng, n, 1.0, h);
  const FilterSoa f = random_filter(rng, n);
  SweepAndPrune incremental;
  std::vector<CandidatePair> pairs, rebuilt;
  incremental.rebuild(to_soa(b), f, pairs);
  // Steps of 1% and of 30% of the box size keep the grid; both must give the rebuild's pairs.
  for (int frame = 0; frame < 6; ++frame) {
    const double step_size = frame < 4 ? 0.01 * h : 0.3 * h;
    for (Aabb& box : b) {
      const Eigen::Vector3d step = uniform3(rng, -1, 1);
      box.min += step * step_size, box.max += step * step_size;
    }
    const AabbSoa s = to_soa(b);
    incremental.update(s, f, pairs);
    EXPECT_TRUE(incremental.stats().incremental) << "frame " << frame;
    SweepAndPrune fresh;
    fresh.rebuild(s, f, rebuilt);
    EXPECT_TRUE(pairs == rebuilt) << describe_difference(pairs, rebuilt);
  }
  EXPECT_TRUE(pairs == brute_force_pairs(to_soa(b), f));
  // A shuffle keeps the grid (the same boxes in another order) and still gives the same pairs.
  for (std::size_t i = b.size(); i > 1; --i) std::swap(b[i - 1], b[rng.index(i)]);  // Fisher-Yates, portable
  const AabbSoa s = to_soa(b);
  incremental.update(s, f, pairs);
  EXPECT_TRUE(incremental.stats().incremental);
  SweepAndPrune fresh;
  fresh.rebuild(s, f, rebuilt);
  EXPECT_TRUE(pairs == rebuilt);
  // The scene drifting far off the grid (all boxes clamped into a border cell) chooses a new grid.
  std::vector<Aabb> far = b;
  for (Aabb& box : far) box.min.x() += 5.0, box.max.x() += 5.0, box.min.y() += 5.0, box.max.y() += 5.0,
                        box.min.z() += 5.0, box.max.z() += 5.0;
  const AabbSoa s_far = to_soa(far);
  incremental.update(s_far, f, pairs);
  EXPECT_FALSE(incremental.stats().incremental);
  EXPECT_TRUE(pairs == brute_force_pairs(s_far, f));
  // A different object count rebuilds.
  b.resize(n / 2);
  const AabbSoa half = to_soa(b);
  FilterSoa f_half = f;
  f_half.group.resize(n / 2), f_half.mask.resize(n / 2), f_half.body.resize(n / 2);
  incremental.update(half, f_half, pairs);
  EXPECT_TRUE(pairs == brute_force_pairs(half, f_half));
}

TEST(SweepAndPrune, MemoryPerObjectStaysUnder64Bytes) {
  Rng rng(9);
  const std::size_t n = 200000;
  const AabbSoa s = to_soa(uniform_boxes(rng, n, 1.0, half_size_for(n, 0.4)));
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(s, {}, pairs);
  sap.update(s, {}, pairs);
  // Honest accounting: every buffer the SAP keeps between frames except those sized by the pairs, plus the 24-byte
  // float boxes it reads; the pair buffers are counted per pair.
  const double per_object = static_cast<double>(sap.memory_bytes() - sap.pair_buffer_bytes()) / n + 24.0;
  const double per_pair = static_cast<double>(sap.pair_buffer_bytes()) / static_cast<double>(pairs.size());
  std::printf("[ info     ] %zu objects, %zu pairs, %zu entries, grid %d x %d: %.1f bytes/object (SAP + boxes), "
              "%.1f bytes/pair\n",
              n, pairs.size(), sap.stats().entries, sap.stats().cells_u, sap.stats().cells_v, per_object, per_pair);
  EXPECT_GT(sap.memory_bytes(), sap.pair_buffer_bytes());
  EXPECT_LE(per_object, 64.0);
}

}  // namespace
}  // namespace batchcol::broadphase
