// The signed-volume projection against a brute-force reference: every subset of the simplex, its affine
// minimum-norm point solved in long double, kept when its weights are non-negative.
#include "kernels/simplex_projection.hpp"
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace batchcol::kernels {
namespace {

using LVec = Eigen::Matrix<long double, 3, 1>;

double brute_force_distance(const std::vector<Eigen::Vector3d>& p) {
  const int n = static_cast<int>(p.size());
  long double best = 1e300L;
  for (int mask = 1; mask < (1 << n); ++mask) {
    std::vector<LVec> s;
    for (int i = 0; i < n; ++i)
      if (mask & (1 << i)) s.push_back(p[i].cast<long double>());
    const int m = static_cast<int>(s.size());
    // Minimise |s0 + sum_k mu_k (s_k - s0)|: normal equations of the edge vectors.
    Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> E(3, m - 1);
    for (int k = 1; k < m; ++k) E.col(k - 1) = s[k] - s[0];
    Eigen::Matrix<long double, Eigen::Dynamic, 1> mu = Eigen::Matrix<long double, Eigen::Dynamic, 1>::Zero(m - 1);
    if (m > 1) {
      const auto G = (E.transpose() * E).eval();
      if (std::abs(G.determinant()) < 1e-30L) continue;  // degenerate subset: covered by its own subsets
      mu = G.ldlt().solve(-E.transpose() * s[0]);
    }
    long double l0 = 1;
    bool feasible = true;
    for (int k = 0; k < m - 1; ++k) { feasible = feasible && mu[k] >= 0; l0 -= mu[k]; }
    if (!feasible || l0 < 0) continue;
    const LVec x = s[0] + (m > 1 ? LVec(E * mu) : LVec::Zero());
    best = std::min(best, x.norm());
  }
  return static_cast<double>(best);
}

TEST(SimplexProjection, MatchesBruteForceOnRandomSimplices) {
  testing::Rng rng(7);
  for (int trial = 0; trial < 4000; ++trial) {
    const int n = 1 + trial % 4;
    std::vector<Eigen::Vector3d> p;
    for (int i = 0; i < n; ++i) p.push_back(Eigen::Vector3d::Random() + Eigen::Vector3d::Constant(trial % 3 == 0 ? 0.0 : 0.7));
    const SimplexProjection<double> r = project_origin(p.data(), n);
    const double ref = brute_force_distance(p);
    ASSERT_NEAR(r.x.norm(), ref, 1e-12) << "trial " << trial;
    double sum = 0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < r.count; ++k) {
      EXPECT_GE(r.lambda[k], 0.0);
      sum += r.lambda[k];
      x += r.lambda[k] * p[r.index[k]];
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    if (!r.contains_origin) EXPECT_LT((x - r.x).norm(), 1e-12);
  }
}

TEST(SimplexProjection, DegenerateSimplicesGiveFiniteConvexCombinations) {
  const Eigen::Vector3d a(1, 1, 1), b(2, 2, 2), c(3, 3, 3), d(1, 1, 1);
  const std::vector<std::vector<Eigen::Vector3d>> cases = {
      {a, a}, {a, a, a}, {a, a, a, a}, {a, b, c}, {a, b, c, d}, {a, b, Eigen::Vector3d(1, 2, 1), Eigen::Vector3d(1.5, 1.5, 1)}};
  for (const auto& p : cases) {
    const auto r = project_origin(p.data(), static_cast<int>(p.size()));
    ASSERT_TRUE(r.x.allFinite());
    EXPECT_NEAR(r.x.norm(), brute_force_distance(p), 1e-12);
  }
}

TEST(SimplexProjection, OriginInsideTetrahedronIsReported) {
  const std::vector<Eigen::Vector3d> p = {{1, 0, 0}, {-1, 1, 0}, {-1, -1, 0.5}, {0, 0, -1}};
  const auto r = project_origin(p.data(), 4);
  EXPECT_TRUE(r.contains_origin);
  EXPECT_EQ(r.x.norm(), 0.0);
  EXPECT_EQ(r.count, 4);
}

TEST(SimplexProjection, FloatVersionStaysWithinFloatRounding) {
  testing::Rng rng(11);
  for (int trial = 0; trial < 1000; ++trial) {
    const int n = 1 + trial % 4;
    std::vector<Eigen::Vector3d> p;
    std::vector<Eigen::Vector3f> pf;
    for (int i = 0; i < n; ++i) {
      p.push_back(Eigen::Vector3d::Random() + Eigen::Vector3d::Constant(0.5));
      pf.push_back(p.back().cast<float>());
    }
    const auto r = project_origin(pf.data(), n);
    EXPECT_NEAR(r.x.norm(), brute_force_distance(p), 2e-6) << trial;
  }
}

}  // namespace
}  // namespace batchcol::kernels
