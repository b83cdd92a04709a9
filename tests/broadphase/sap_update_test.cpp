// SweepAndPrune::update() without re-bucketing (records refreshed in place, objects that left their cells in the
// overflow, re-bucketing when the overflow grows): equal to a fresh rebuild and to brute force after small, large
// and growing motions, for 1 and 2 threads, and the nearly-sorted cell sort falling back to the radix sort.
#include "broadphase/sap_scenes.hpp"

#include "broadphase/brute_force.hpp"
#include "broadphase/sweep_and_prune.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <vector>

namespace batchcol::broadphase {
namespace {

using namespace testing;

std::vector<CandidatePair> rebuilt(const AabbSoa& s, const FilterSoa& f) {
  SweepAndPrune fresh;
  std::vector<CandidatePair> pairs;
  fresh.rebuild(s, f, pairs);
  return pairs;
}

void move_all(Rng& rng, std::vector<Aabb>& b, double step) {
  for (Aabb& box : b) {
    const Eigen::Vector3d d = uniform3(rng, -1, 1);
    box.min += d * step, box.max += d * step;
  }
}

TEST(SapUpdate, SmallMotionsKeepTheCellsAndEqualBruteForce) {
  Rng rng(11);
  const std::size_t n = 8000;
  const double h = half_size_for(n, 0.4);
  std::vector<Aabb> b = uniform_boxes(rng, n, 1.0, h);
  const FilterSoa f = random_filter(rng, n);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(to_soa(b), f, pairs);
  std::size_t refreshed = 0, with_overflow = 0;
  for (int frame = 0; frame < 8; ++frame) {
    move_all(rng, b, 0.1 * h);
    const AabbSoa s = to_soa(b);
    sap.update(s, f, pairs);
    refreshed += sap.stats().rebucketed ? 0 : 1;
    with_overflow += sap.stats().overflow > 0 ? 1 : 0;
    ASSERT_EQ(pairs, brute_force_pairs(s, f)) << "frame " << frame;
  }
  EXPECT_EQ(refreshed, 8u);  // small motions never need a re-bucketing
  EXPECT_GT(with_overflow, 0u);  // but some boxes cross cell borders: the overflow path ran
}

TEST(SapUpdate, LargeMotionsFillTheOverflowThenRebucketAndEqualRebuild) {
  Rng rng(12);
  const std::size_t n = 6000;
  const double h = half_size_for(n, 1.0);
  std::vector<Aabb> b = uniform_boxes(rng, n, 1.0, h);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(to_soa(b), {}, pairs);
  std::size_t refreshed = 0, rebucketed = 0;
  for (int frame = 0; frame < 12; ++frame) {
    // Teleport 3% of the boxes anywhere, move the rest by 5% of their size.
    move_all(rng, b, 0.05 * h);
    for (std::size_t k = 0; k < n / 33; ++k) {
      Aabb& box = b[rng() % n];
      const Eigen::Vector3d jump = uniform3(rng, -0.5, 0.5);
      box.min += jump, box.max += jump;
    }
    const AabbSoa s = to_soa(b);
    sap.update(s, {}, pairs);
    (sap.stats().rebucketed ? rebucketed : refreshed) += 1;
    ASSERT_EQ(pairs, rebuilt(s, {})) << "frame " << frame;
    ASSERT_EQ(pairs, brute_force_pairs(s)) << "frame " << frame;
  }
  EXPECT_GT(refreshed, 0u);
  EXPECT_GT(rebucketed, 0u);  // the overflow passed 1/8 of the objects at least once
}

TEST(SapUpdate, BoxesGrowingAcrossManyCellsAndShrinking) {
  Rng rng(13);
  const std::size_t n = 5000;
  const double h = half_size_for(n, 0.4);
  std::vector<Aabb> b = uniform_boxes(rng, n, 1.0, h);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(to_soa(b), {}, pairs);
  for (int frame = 0; frame < 4; ++frame) {
    // A few boxes grow to a quarter of the world (they span many cells), then shrink back to points.
    for (std::size_t k = frame; k < n; k += 400) {
      const Eigen::Vector3d c = 0.5 * (b[k].min + b[k].max);
      const double half = frame % 2 == 0 ? 0.125 : 0.0;
      b[k] = box_at(c, Eigen::Vector3d::Constant(half));
    }
    const AabbSoa s = to_soa(b);
    sap.update(s, {}, pairs);
    ASSERT_EQ(pairs, brute_force_pairs(s)) << "frame " << frame;
  }
}

TEST(SapUpdate, ReversedOrderInsideAHugeCellFallsBackToTheRadixSort) {
  // All boxes on a line along x: the grid has one cell, which holds every box. Reversing the order of the x positions
  // keeps every cell range but makes the previous order the worst case for insertion sort.
  std::vector<Aabb> b;
  const Eigen::Vector3d h(0.1, 0.1, 0.1);
  for (int i = 0; i < 5000; ++i) b.push_back(box_at({0.15 * i, 0, 0}, h));
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(to_soa(b), {}, pairs);
  for (int i = 0; i < 5000; ++i) b[i] = box_at({0.15 * (4999 - i), 0, 0}, h);
  const AabbSoa s = to_soa(b);
  sap.update(s, {}, pairs);
  EXPECT_FALSE(sap.stats().rebucketed);
  EXPECT_EQ(sap.stats().overflow, 0u);
  EXPECT_EQ(pairs, brute_force_pairs(s));
}

TEST(SapUpdate, SameUpdatesForOneAndTwoThreads) {
  Rng rng(14);
  const std::size_t n = 100000;
  const double h = half_size_for(n, 0.4);
  std::vector<std::vector<Aabb>> frames = {uniform_boxes(rng, n, 1.0, h)};
  for (int k = 0; k < 4; ++k) {
    frames.push_back(frames.back());
    move_all(rng, frames.back(), 0.3 * h);
  }
  const FilterSoa f = random_filter(rng, n);
  std::vector<std::vector<CandidatePair>> results[2];
  for (int t : {1, 2}) {
    tbb::task_arena(t).execute([&] {
      SweepAndPrune sap;
      std::vector<CandidatePair> pairs;
      sap.rebuild(to_soa(frames[0]), f, pairs);
      results[t - 1].push_back(pairs);
      for (std::size_t k = 1; k < frames.size(); ++k) {
        sap.update(to_soa(frames[k]), f, pairs);
        results[t - 1].push_back(pairs);
      }
    });
  }
  ASSERT_EQ(results[0].size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_FALSE(results[0][k].empty());
    EXPECT_TRUE(results[0][k] == results[1][k]) << "frame " << k;
    EXPECT_TRUE(results[0][k] == rebuilt(to_soa(frames[k]), f)) << "frame " << k;
  }
}

}  // namespace
}  // namespace batchcol::broadphase
