// Broad-phase input: float keys ordered like floats, outward rounding of double boxes, the radix sort, and bad
// input rejected at the boundary with the offending object's index.
#include "broadphase/sap_scenes.hpp"

#include "batchcol/errors.hpp"
#include "broadphase/brute_force.hpp"
#include "broadphase/float_key.hpp"
#include "broadphase/radix_sort.hpp"
#include "broadphase/sweep_and_prune.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

namespace batchcol::broadphase {
namespace {

using namespace testing;

TEST(BroadphaseFloatKey, OrderedLikeFloatsIncludingNegativesZerosAndExtremes) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> v = {-FLT_MAX, -1e30f, -2.0f, -1.0f, -FLT_MIN, -1e-45f, 0.0f, 1e-45f, FLT_MIN, 1.0f, 2.0f,
                          1e30f, FLT_MAX};
  Rng rng(1);
  for (int i = 0; i < 2000; ++i) v.push_back(static_cast<float>(uniform(rng, -1e6, 1e6)));
  for (float a : v)
    for (float b : {v[0], v[3], v[6], v[8], v[12], a * 0.5f, std::nextafter(a, inf), std::nextafter(a, -inf)}) {
      ASSERT_EQ(a < b, sortable_key(a) < sortable_key(b)) << a << " " << b;
      ASSERT_EQ(a == b, sortable_key(a) == sortable_key(b)) << a << " " << b;
      ASSERT_EQ(key_to_float(sortable_key(a)), a);
    }
  EXPECT_EQ(sortable_key(-0.0f), sortable_key(0.0f));
}

TEST(BroadphaseAabb, DoubleBoxesRoundOutwardToFloat) {
  Rng rng(2);
  for (int i = 0; i < 10000; ++i) {
    const double x = uniform(rng, -1e3, 1e3) * std::pow(10.0, static_cast<int>(rng() % 20) - 10);
    EXPECT_LE(static_cast<double>(float_down(x)), x);
    EXPECT_GE(static_cast<double>(float_up(x)), x);
    if (static_cast<double>(float_down(x)) != x) {  // tight: the next float up is already above x
      EXPECT_GT(static_cast<double>(std::nextafter(float_down(x), FLT_MAX)), x);
    }
  }
  EXPECT_FALSE(std::signbit(float_down(-0.0)));
  EXPECT_FALSE(std::signbit(float_up(-1e-300)));  // rounds up to -0, stored as +0
  AabbSoa s;
  s.resize(1);
  s.set(0, Aabb{Eigen::Vector3d(0.1, -0.1, 1.0 / 3), Eigen::Vector3d(0.2, 0.3, 2.0 / 3)}, 0.05);
  EXPECT_LE(s.min_x[0], 0.1 - 0.05);
  EXPECT_GE(s.max_y[0], 0.3 + 0.05);
}

TEST(BroadphaseRadixSort, EqualsStableSortOnChosenDigits) {
  Rng rng(3);
  for (std::size_t n : {0, 1, 5, 64, 65, 1000, 100000, 300000}) {
    std::vector<std::uint64_t> v(n), scratch(n);
    for (auto& x : v) x = rng() & 0x00ff00ffffff00ffull;  // some constant digits: those passes are skipped
    for (const auto& shifts : {digit_shifts(32, 64), digit_shifts(0, 64), std::vector<int>{0, 48}}) {
      std::uint64_t mask = 0;
      for (int s : shifts) mask |= std::uint64_t{0xff} << s;
      std::vector<std::uint64_t> want = v;
      std::stable_sort(want.begin(), want.end(), [&](auto a, auto b) { return (a & mask) < (b & mask); });
      std::vector<std::uint64_t> one = v, two = v;
      tbb::task_arena(1).execute([&] { radix_sort(one.data(), scratch.data(), n, shifts); });
      tbb::task_arena(2).execute([&] { radix_sort(two.data(), scratch.data(), n, shifts); });
      EXPECT_EQ(one, want) << n;
      EXPECT_EQ(two, want) << n;
    }
  }
}

void expect_rejected(const AabbSoa& s, const std::string& needle) {
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  for (int k = 0; k < 3; ++k) {
    try {
      if (k == 0) sap.rebuild(s, {}, pairs);
      if (k == 1) sap.update(s, {}, pairs);
      if (k == 2) brute_force_pairs(s);
      ADD_FAILURE() << "accepted: " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
}

TEST(BroadphaseAabb, BadInputIsRejectedNamingTheObject) {
  Rng rng(4);
  const AabbSoa good = to_soa(uniform_boxes(rng, 5000, 1.0, 0.01));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  {
    AabbSoa s = good;
    s.min_y[4321] = nan;
    s.max_z[4400] = nan;
    expect_rejected(s, "object 4321: min.y");
  }
  {
    AabbSoa s = good;
    s.max_x[17] = inf;
    expect_rejected(s, "object 17: max.x = inf is not finite");
  }
  {
    AabbSoa s = good;
    s.min_z[9] = -inf;
    s.max_z[9] = -inf;
    expect_rejected(s, "object 9: min.z");
  }
  {
    AabbSoa s = good;
    s.min_z[3] = s.max_z[3] + 1.0f;
    expect_rejected(s, "object 3: min.z");
    expect_rejected(s, "> max.z");
  }
  {
    AabbSoa s = good;
    s.max_y.pop_back();
    expect_rejected(s, "same size");
  }
  // The double-box boundary checks too.
  AabbSoa s;
  s.resize(3);
  const double dnan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(s.set(2, Aabb{Eigen::Vector3d(0, dnan, 0), Eigen::Vector3d(1, 1, 1)}), InputError);
  try {
    s.assign(std::vector<Aabb>{Aabb{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()},
              Aabb{Eigen::Vector3d::Zero(), Eigen::Vector3d(1, -1, 1)}});
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("object 1: min.y = 0 > max.y = -1"), std::string::npos) << e.what();
  }
  try {
    const double big = std::numeric_limits<double>::infinity();
    s.assign(std::vector<Aabb>{Aabb{Eigen::Vector3d::Constant(-big), Eigen::Vector3d::Constant(big)}});  // a halfspace's box
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("object 0: min.x = -inf is not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW(s.set(0, Aabb{Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1e39)}), InputError);  // beyond float
  EXPECT_THROW(s.set(0, Aabb{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()}, -1.0), InputError);   // negative margin
}

TEST(BroadphaseAabb, FilterOfTheWrongSizeIsRejected) {
  Rng rng(5);
  const AabbSoa s = to_soa(uniform_boxes(rng, 10, 1.0, 0.1));
  FilterSoa f = random_filter(rng, 9);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  EXPECT_THROW(sap.rebuild(s, f, pairs), InputError);
  f = random_filter(rng, 10);
  f.mask.pop_back();
  EXPECT_THROW(sap.rebuild(s, f, pairs), InputError);
  EXPECT_THROW(brute_force_pairs(s, f), InputError);
}

}  // namespace
}  // namespace batchcol::broadphase
