// The portable random source (tools/testkit/portable_random.hpp): its raw draws are the standard's mt19937_64
// sequence, and its derived draws stay in their ranges and are reproducible from the seed.
#include "testkit/portable_random.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace batchcol::testkit {
namespace {

TEST(PortableRandom, RawDrawsAreTheStandardSequence) {
  // [rand.predef]: the 10000th consecutive invocation of a default-constructed mt19937_64 (seed 5489) produces
  // 9981545732273789042 on every conforming standard library.
  PortableRandom rng(5489u);
  std::uint64_t x = 0;
  for (int i = 0; i < 10000; ++i) x = rng();
  EXPECT_EQ(x, 9981545732273789042ull);
}

TEST(PortableRandom, UniformUsesTheTop53BitsOfEachDraw) {
  PortableRandom a(77), b(77);
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t bits = a();
    EXPECT_EQ(b.uniform(), static_cast<double>(bits >> 11) * 0x1.0p-53);
  }
}

TEST(PortableRandom, DrawsStayInTheirRanges) {
  PortableRandom rng(3);
  for (int i = 0; i < 20000; ++i) {
    const double u = rng.uniform(-2.5, 4.0);
    ASSERT_GE(u, -2.5);
    ASSERT_LT(u, 4.0);
    ASSERT_LT(rng.index(7), 7u);
    ASSERT_NEAR(rng.unit_vector().norm(), 1.0, 1e-15);
    ASSERT_NEAR(rng.rotation().norm(), 1.0, 1e-15);
  }
}

TEST(PortableRandom, IndicesCoverTheRangeEvenly) {
  PortableRandom rng(11);
  int count[5] = {};
  const int n = 50000;
  for (int i = 0; i < n; ++i) ++count[rng.index(5)];
  // Binomial(50000, 0.2): standard deviation ~89; 6 sigma bounds cannot fail by chance in practice.
  for (int c : count) EXPECT_NEAR(c, n / 5, 540);
}

TEST(PortableRandom, RotationsAreUniform) {
  // For a uniformly distributed rotation, E[R] = 0, so the mean of R e_x over many draws tends to zero
  // (each component has variance 1/3: 6 sigma of the mean of 40000 draws is 0.017).
  PortableRandom rng(5);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  const int n = 40000;
  for (int i = 0; i < n; ++i) mean += rng.rotation() * Eigen::Vector3d::UnitX() / n;
  EXPECT_LT(mean.norm(), 0.03);
}

TEST(PortableRandom, SameSeedSameSequenceOtherSeedOtherSequence) {
  PortableRandom a(42), b(42), c(43);
  int differ = 0;
  for (int i = 0; i < 100; ++i) {
    const double x = a.uniform();
    EXPECT_EQ(x, b.uniform());
    differ += x != c.uniform();
  }
  EXPECT_GT(differ, 95);
}

}  // namespace
}  // namespace batchcol::testkit
