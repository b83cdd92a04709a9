// GJK's signed-volume projection step against a brute-force reference: every subset of the simplex, its affine
// minimum-norm point solved in long double, kept when its weights are non-negative. The step only considers
// sub-simplices that keep the newest vertex p[n-1]: it must find the true closest point whenever that point's
// support set contains p[n-1], and otherwise return a point of the simplex (or no candidate for a tetrahedron).
#include "support/reference_simplex_projection.hpp"
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace batchcol::test_reference {
namespace {

using LVec = Eigen::Matrix<long double, 3, 1>;

struct BruteForce {
  double distance;
  int support;  // bit mask of the closest point's support set
};

BruteForce brute_force(const std::vector<Eigen::Vector3d>& p) {
  const int n = static_cast<int>(p.size());
  long double best = 1e300L;
  int support = 0;
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
    if (x.norm() < best) best = x.norm(), support = mask;
  }
  return {static_cast<double>(best), support};
}

/// Checks r against the brute force; returns whether the true closest point keeps the newest vertex.
bool check_step(const std::vector<Eigen::Vector3d>& p, const SimplexProjection<double>& r, double tol, int trial) {
  const int n = static_cast<int>(p.size());
  const BruteForce ref = brute_force(p);
  const bool keeps_newest = (ref.support >> (n - 1)) & 1;
  if (keeps_newest) { EXPECT_NEAR(r.x.norm(), ref.distance, tol) << "trial " << trial; }
  if (r.count == 0) {  // no candidate: only a tetrahedron whose closest point lies on the old face
    EXPECT_EQ(n, 4) << "trial " << trial;
    EXPECT_FALSE(keeps_newest) << "trial " << trial;
    EXPECT_TRUE(std::isinf(r.x.norm())) << "trial " << trial;
    return keeps_newest;
  }
  EXPECT_GE(r.x.norm(), ref.distance - tol) << "trial " << trial;
  return keeps_newest;
}

TEST(SimplexProjection, MatchesBruteForceOnRandomSimplices) {
  testing::Rng rng(7);
  int exact = 0, skipped = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const int n = 1 + trial % 4;
    std::vector<Eigen::Vector3d> p;
    for (int i = 0; i < n; ++i) p.push_back(testing::random_vector(rng) + Eigen::Vector3d::Constant(trial % 3 == 0 ? 0.0 : 0.7));
    const SimplexProjection<double> r = project_origin(p.data(), n);
    (check_step(p, r, 1e-12, trial) ? exact : skipped) += 1;
    if (r.count == 0) continue;
    double sum = 0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < r.count; ++k) {
      EXPECT_GE(r.lambda[k], 0.0);
      sum += r.lambda[k];
      x += r.lambda[k] * p[r.index[k]];
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    if (!r.contains_origin) { EXPECT_LT((x - r.x).norm(), 1e-12); }
  }
  EXPECT_GT(exact, 2000);  // most random simplices have their closest point on the newest vertex's side
  EXPECT_GT(skipped, 100);
}

TEST(SimplexProjection, OldFaceClosestGivesNoCandidate) {
  // The origin sees only face 0-1-2 (below it); vertex 3 is on the far side: nothing keeping vertex 3 is closer.
  const std::vector<Eigen::Vector3d> p = {{-1, -1, 1}, {1, -1, 1}, {0, 1, 1}, {0, 0, 3}};
  const auto r = project_origin(p.data(), 4);
  EXPECT_EQ(r.count, 0);
  EXPECT_FALSE(r.contains_origin);
  EXPECT_TRUE(std::isinf(r.x.norm()));
  // Same points with the roles swapped (vertex 0 newest on the near face): the closest point keeps it.
  const std::vector<Eigen::Vector3d> q = {{0, 0, 3}, {-1, -1, 1}, {1, -1, 1}, {0, 1, 1}};
  const auto s = project_origin(q.data(), 4);
  EXPECT_EQ(s.count, 3);
  EXPECT_NEAR(s.x.norm(), 1.0, 1e-15);
}

TEST(SimplexProjection, FirstFaceMissedGivesTheClosestVisibleEdge) {
  // The origin sees faces 0 (p1 p2 p3) and 2 (p0 p1 p3), face 2's plane the farther (squared distances 0.059 and
  // 0.191): face 2 is the first face and the origin's projection falls outside it. The answer is then the closest
  // of the visible faces' edges k-3, the first of equal ones: vertex p0 (edge 0-3), as far as vertex p1 (edge 1-3,
  // face 0's own answer), its mirror image (x -> -x). Before, every visible face was solved again in order and
  // face 0's p1 won the tie.
  const std::vector<Eigen::Vector3d> p = {
      {-0.375, -0.25, -0.375}, {0.375, -0.25, -0.375}, {1.875, -1.25, -0.125}, {0.0, 1.0, -1.75}};
  const auto r = project_origin(p.data(), 4);
  EXPECT_FALSE(r.contains_origin);
  EXPECT_EQ(r.count, 1);
  EXPECT_EQ(r.index[0], 0);
  EXPECT_EQ(r.x, p[0]);
}

TEST(SimplexProjection, TriangleWeightsAreTripleProductsAtTheFoot) {
  // The face weights are C_i = <r, n x b>, C_j = <r, a x n>, C_k = |n|^2 - C_i - C_j with a, b the edges at the
  // newest vertex p2, n = a x b and r = p2 - p0 (p0 = the origin's foot on the plane), over their sum: bit for bit
  // (the SIMD kernel repeats them). The old rule (signed areas on the best coordinate plane) rounds otherwise and
  // fails here; both are exact in exact arithmetic.
  testing::Rng rng(19);
  int faces = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d u = testing::random_unit_vector(rng), e = u.cross(testing::random_unit_vector(rng)).normalized();
    const Eigen::Vector3d f = u.cross(e), foot = 0.3 * u;
    // Around the foot, so that most triangles hold it: their answer is the face.
    const std::vector<Eigen::Vector3d> p = {foot + 0.4 * (-e - f) + 0.1 * testing::random_vector(rng),
                                            foot + 0.4 * (e - f) + 0.1 * testing::random_vector(rng),
                                            foot + 0.4 * f + 0.1 * testing::random_vector(rng)};
    const auto r = project_origin(p.data(), 3);
    if (r.count != 3) continue;
    ++faces;
    const Eigen::Vector3d a = p[0] - p[2], b = p[1] - p[2], n = cross3<double>(a, b);
    const double nn = norm2(n);
    const Eigen::Vector3d rk = p[2] - n * (dot3(p[2], n) / nn);
    const double ci = dot3(rk, cross3<double>(n, b)), cj = dot3(rk, cross3<double>(a, n)), ck = (nn - ci) - cj;
    const double inv = 1.0 / (ci + cj + ck);
    EXPECT_EQ(r.lambda[0], ci * inv) << trial;
    EXPECT_EQ(r.lambda[1], cj * inv) << trial;
    EXPECT_EQ(r.lambda[2], ck * inv) << trial;
  }
  EXPECT_GT(faces, 150);
}

TEST(SimplexProjection, DegenerateSimplicesGiveFiniteConvexCombinations) {
  const Eigen::Vector3d a(1, 1, 1), b(2, 2, 2), c(3, 3, 3), d(1, 1, 1);
  const std::vector<std::vector<Eigen::Vector3d>> cases = {
      {a, a}, {a, a, a}, {a, a, a, a}, {a, b, c}, {a, b, c, d}, {a, b, Eigen::Vector3d(1, 2, 1), Eigen::Vector3d(1.5, 1.5, 1)}};
  for (const auto& p : cases) {
    const auto r = project_origin(p.data(), static_cast<int>(p.size()));
    ASSERT_TRUE(r.x.allFinite());
    check_step(p, r, 1e-12, 0);
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
      p.push_back(testing::random_vector(rng) + Eigen::Vector3d::Constant(0.5));
      pf.push_back(p.back().cast<float>());
    }
    const auto r = project_origin(pf.data(), n);
    const BruteForce ref = brute_force(p);
    if ((ref.support >> (n - 1)) & 1) { EXPECT_NEAR(r.x.norm(), ref.distance, 2e-6) << trial; }
    else if (r.count > 0) { EXPECT_GE(r.x.norm(), ref.distance - 2e-6) << trial; }
  }
}

}  // namespace
}  // namespace batchcol::test_reference
