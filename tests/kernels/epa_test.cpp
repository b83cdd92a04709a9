// Penetration depths with known answers: polytope pairs (exact EPA) and curved shapes (EPA converges on a
// polytope approximation, with the error bounded by its tolerance).
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;

QueryOptions depth_options(double tolerance = 1e-10) {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.tolerance = tolerance;
  o.closed_forms = false;
  o.max_iterations = 1000;
  o.epa_max_iterations = 2000;
  return o;
}

/// Checks a penetration result against the expected depth and normal (world frame).
void expect_depth(const testing::SingleResult& r, double depth, const Eigen::Vector3d& normal, double tol) {
  EXPECT_EQ(r.status, Status::converged);
  EXPECT_TRUE(r.collide);
  EXPECT_NEAR(r.distance, -depth, tol);
  EXPECT_GT(r.normal.dot(normal), 1 - 1e-6) << r.normal.transpose();
  EXPECT_LT((r.witness_b - r.witness_a - r.distance * r.normal).norm(), 1e-9);
}

TEST(Epa, AxisAlignedBoxesUnderACommonRotation) {
  Rng rng(3);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Vector3d ha = testing::random_vector(rng).cwiseAbs() * 0.2 + Eigen::Vector3d::Constant(0.02);
    const Eigen::Vector3d hb = testing::random_vector(rng).cwiseAbs() * 0.2 + Eigen::Vector3d::Constant(0.02);
    const Eigen::Vector3d c = testing::random_vector(rng).cwiseProduct(ha + hb) * 0.95;  // overlapping centres
    // D is the box of half extents ha + hb centred at -c: the depth is the smallest exit distance.
    Eigen::Vector3d room = (ha + hb) - c.cwiseAbs();
    int axis;
    const double depth = room.minCoeff(&axis);
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[axis] = c[axis] < 0 ? -1 : 1;
    const Eigen::Quaterniond Q = testing::random_rotation(rng);
    const Eigen::Vector3d T = testing::random_vector(rng) * 100;
    const auto r = testing::run_pair(Shape::box(ha), Pose{T, Q}, Shape::box(hb), Pose{T + Q * c, Q}, depth_options());
    // Ties between axes make the normal ambiguous; only compare it when the minimum is clear.
    room[axis] = 1e9;
    SCOPED_TRACE(trial);
    if (room.minCoeff() - depth > 1e-6) expect_depth(r, depth, Q * n, 1e-9);
    else EXPECT_NEAR(r.distance, -depth, 1e-9);
  }
}

TEST(Epa, SphereInsideBoxThroughGjkAndEpa) {
  const Shape box = Shape::box(0.3, 0.2, 0.1);
  for (double z : {0.0, 0.05, 0.09, -0.099}) {
    const Shape ball = Shape::sphere(0.05);
    const auto r = testing::run_pair(box, Pose{}, ball, Pose::from_translation({0.01, -0.02, z}), depth_options());
    const double depth = (0.1 - std::abs(z)) + 0.05;
    // At z = 0 leaving up or down is equally short: the normal is +z or -z.
    const Eigen::Vector3d n(0, 0, z < 0 || (z == 0 && r.normal.z() < 0) ? -1 : 1);
    expect_depth(r, depth, n, 1e-9);
  }
}

TEST(Epa, CrossingCapsulesHaveDepthOfTheirRadii) {
  // Cores are crossing segments: D is flat, its depth 0, and the normal is perpendicular to both axes.
  const Shape a = Shape::capsule(0.05, 0.3), b = Shape::capsule(0.03, 0.2);
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  const auto r = testing::run_pair(a, Pose{}, b, Pose{Eigen::Vector3d(0.02, 0, 0.1), turn}, depth_options());
  expect_depth(r, 0.08 - 0.02 + 0.0, Eigen::Vector3d::UnitX(), 1e-12);
}

TEST(Epa, CurvedShapesDeepAndShallow) {
  Rng rng(8);
  const QueryOptions opt = depth_options(1e-9);
  for (double depth : {1e-6, 1e-4, 1e-2, 0.1}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Quaterniond Q = testing::random_rotation(rng);
      const Eigen::Vector3d T = testing::random_vector(rng);
      const Eigen::Vector3d e = Q * Eigen::Vector3d::UnitZ();
      SCOPED_TRACE("depth " + std::to_string(depth) + " trial " + std::to_string(trial));
      {  // Two ellipsoids with equal radii are balls: depth = ra + rb - d.
        const double ra = testing::uniform(rng, 0.05, 0.2), rb = testing::uniform(rng, 0.05, 0.2);
        const auto r = testing::run_pair(Shape::ellipsoid(ra, ra, ra), Pose{T, Q}, Shape::ellipsoid(rb, rb, rb),
                                         Pose{T + e * (ra + rb - depth), testing::random_rotation(rng)}, opt);
        expect_depth(r, depth, e, 1e-7);
      }
      {  // Coaxial cylinders stacked along their axis: the axial overlap is the shallowest exit.
        const auto r = testing::run_pair(Shape::cylinder(0.2, 0.1), Pose{T, Q}, Shape::cylinder(0.15, 0.2),
                                         Pose{T + e * (0.3 - depth), Q}, opt);
        if (depth < 0.15) expect_depth(r, depth, e, 1e-7);
      }
      {  // A cone's apex pushed into a large box face: the apex depth.
        const auto r = testing::run_pair(Shape::box(2, 2, 0.5), Pose{T, Q}, Shape::cone(0.1, 0.1),
                                         Pose{T + e * (0.5 + 0.1 - depth), Q * Eigen::Quaterniond(0, 1, 0, 0)}, opt);
        expect_depth(r, depth, e, 1e-7);
      }
      {  // An ellipsoid pressed into a large box face along one of its axes.
        const auto r = testing::run_pair(Shape::box(2, 2, 0.5), Pose{T, Q}, Shape::ellipsoid(0.1, 0.05, 0.2),
                                         Pose{T + e * (0.5 + 0.2 - depth), Q}, opt);
        expect_depth(r, depth, e, 1e-7);
      }
    }
  }
}

TEST(Epa, TouchingPolytopesHaveZeroDepth) {
  const auto r = testing::run_pair(Shape::box(0.1, 0.1, 0.1), Pose{}, Shape::box(0.1, 0.1, 0.1),
                                   Pose::from_translation({0.2, 0.05, 0}), depth_options());
  EXPECT_EQ(r.status, Status::converged);
  EXPECT_NEAR(r.distance, 0.0, 1e-12);
  EXPECT_TRUE(r.collide);
}

}  // namespace
}  // namespace batchcol

namespace batchcol {
namespace {

TEST(Epa, ExactlyAlignedBoxesRegression) {
  // Found by the CLI tests: with no rotation at all, EPA met a cone face whose corners are collinear (new point on
  // the line of a horizon edge) and stopped with a depth of 0.2/sqrt(3). The face behind that edge is now removed too.
  const Shape cube = Shape::box(0.5, 0.5, 0.5);
  const std::vector<std::pair<Eigen::Vector3d, double>> cases = {
      {{0.8, 0, 0}, 0.2}, {{0, 0, 0}, 1.0}, {{0, 0.3, 0}, 0.7}, {{0, 0, -0.95}, 0.05}, {{0.8, 0.1, 0.05}, 0.2}};
  for (const auto& [t, depth] : cases)
    for (Solver s : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      QueryOptions o = depth_options();
      o.solver = s;
      const auto r = testing::run_pair(cube, Pose{}, cube, Pose::from_translation(t), o);
      EXPECT_EQ(r.status, Status::converged) << t.transpose();
      EXPECT_NEAR(r.distance, -depth, 1e-12) << t.transpose();
    }
}

// Two identical cylinders at one pose: the depth is the diameter 2r, attained along every radial direction (a
// circle of minimal directions). EPA's lower bound closes only as 1 / expansions^2 there (1.9e-6 m at 1000), so at
// tolerance 1e-12 the budget always runs out: the status says so, and the depth is the best upper bound, exact.
TEST(Epa, IdenticalCylindersRunOutOfBudgetWithTheExactDepth) {
  Rng rng(12);
  for (int trial = 0; trial < 6; ++trial) {
    const double r = testing::uniform(rng, 0.02, 0.1), h = testing::uniform(rng, 0.2, 0.5);
    const Shape rod = Shape::cylinder(r, h);
    const Pose pose{testing::random_vector(rng), testing::random_rotation(rng)};
    for (int budget : {1000, 2000}) {
      QueryOptions o = depth_options(1e-12);
      o.epa_max_iterations = budget;
      const auto res = testing::run_pair(rod, pose, rod, pose, o);
      SCOPED_TRACE("trial " + std::to_string(trial) + " budget " + std::to_string(budget));
      EXPECT_EQ(res.status, Status::max_iterations);
      EXPECT_TRUE(res.collide);
      EXPECT_NEAR(res.distance, -2 * r, 1e-12);  // measured 1.4e-17 (the lower bound alone: 2e-6 at 1000)
      EXPECT_LT(std::abs(res.normal.dot(pose.rotation * Eigen::Vector3d::UnitZ())), 1e-9);  // radial
      EXPECT_LT((res.witness_b - res.witness_a - res.distance * res.normal).norm(), 1e-12);
    }
  }
}

// Whatever the budget, a depth returned with max_iterations is an upper bound (moving b by it along the normal
// separates the pair) and within the reference by no more than the approximation left: checked on random curved
// pairs with budgets of 3..30 expansions against the same pair at tolerance 1e-9 and 5000 expansions.
TEST(Epa, OutOfBudgetDepthIsASeparatingUpperBound) {
  Rng rng(13);
  const std::vector<ShapeType> curved = {ShapeType::cylinder, ShapeType::cone, ShapeType::ellipsoid, ShapeType::box,
                                         ShapeType::convex};
  int out_of_budget = 0;
  double worst_ratio = 1.0;  // reported depth / reference depth
  for (int trial = 0; trial < 300; ++trial) {
    const Shape a = testing::random_shape(rng, curved[trial % curved.size()]);
    const Shape b = testing::random_shape(rng, curved[(trial / 5) % curved.size()]);
    const Pose pa{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    const Pose pb{0.05 * testing::random_unit_vector(rng), testing::random_rotation(rng)};
    QueryOptions reference = depth_options(1e-9);
    reference.epa_max_iterations = 5000;
    const auto ref = testing::run_pair(a, pa, b, pb, reference);
    if (!ref.collide || ref.status != Status::converged) continue;
    QueryOptions tight = depth_options(1e-12);
    tight.epa_max_iterations = 3 + trial % 28;
    const auto r = testing::run_pair(a, pa, b, pb, tight);
    if (r.status != Status::max_iterations) continue;
    ++out_of_budget;
    SCOPED_TRACE("trial " + std::to_string(trial));
    ASSERT_TRUE(std::isfinite(r.distance) && r.normal.allFinite());
    EXPECT_LE(r.distance, ref.distance + 1e-9);  // at least as deep as the truth: an upper bound on the depth
    // And not absurdly deep. With 3 expansions the bound comes from a handful of support directions, so its ratio
    // to the truth depends on the draw (1.87x and 2.08x at worst on two random streams): 3x is the check.
    EXPECT_GE(r.distance, 3 * ref.distance - 1e-9);
    worst_ratio = std::max(worst_ratio, r.distance / ref.distance);
    Pose moved = pb;
    moved.translation += (-r.distance + 1e-9) * r.normal;  // push b out by the reported depth (world frame)
    QueryOptions check = depth_options(1e-10);
    check.level = QueryLevel::distance;
    EXPECT_FALSE(testing::run_pair(a, pa, b, moved, check).collide) << "depth " << -r.distance;
  }
  EXPECT_GT(out_of_budget, 100);
  std::printf("[measured] %d pairs out of budget: depth at most %.3g x the reference\n", out_of_budget, worst_ratio);
}

}  // namespace
}  // namespace batchcol
