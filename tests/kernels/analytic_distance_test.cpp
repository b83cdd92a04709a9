// Closed-form distances for every shape-pair family. Two shapes that are both symmetric under the reflections
// fixing the line through their centres have their closest points on that line (the minimum-norm point of the
// Minkowski difference is unique, hence invariant), so their distance is the gap between their extents along it:
// dist = L - h_A(e) - h_B(-e). Each configuration is then moved by a random common rigid transform.
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol {
namespace {

using testing::Rng;

/// Proper rotations mapping coordinate axes to coordinate axes (the 24 rotations of the cube).
std::vector<Eigen::Matrix3d> axis_rotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int c = 0; c < 3; ++c) R(p[c], c) = (signs >> c) & 1 ? -1.0 : 1.0;
      if (R.determinant() > 0) out.push_back(R);
    }
  return out;
}

/// A rotation of the allowed set that keeps the shape symmetric about the world x axis.
Eigen::Matrix3d symmetric_rotation(Rng& rng, ShapeType type) {
  static const std::vector<Eigen::Matrix3d> rotations = axis_rotations();
  for (;;) {
    const Eigen::Matrix3d& R = rotations[rng() % rotations.size()];
    // A cone is symmetric only about its own axis: that axis must map onto the line of centres.
    if (type != ShapeType::cone || std::abs(R(0, 2)) == 1.0) return R;
  }
}

struct Config {
  Shape a, b;
  Pose pa, pb;
  double distance;
};

Config make_config(Rng& rng, ShapeType ta, ShapeType tb, double gap) {
  Config c{testing::symmetric_shape(rng, ta), testing::symmetric_shape(rng, tb), {}, {}, 0};
  if (rng() % 3 == 0) c.a = c.a.inflated(testing::uniform(rng, 0.0, 0.05));
  const Eigen::Matrix3d Ra = symmetric_rotation(rng, ta), Rb = symmetric_rotation(rng, tb);
  const Eigen::Vector3d e = Eigen::Vector3d::UnitX();
  const double ha = testing::extent(c.a, Ra.transpose() * e), hb = testing::extent(c.b, Rb.transpose() * -e);
  const double L = ha + hb + gap;
  const Eigen::Quaterniond Q = testing::random_rotation(rng);
  const Eigen::Vector3d T = testing::random_vector(rng) * 10;
  c.pa = {T, Q * Eigen::Quaterniond(Ra)};
  c.pb = {T + Q * (L * e), Q * Eigen::Quaterniond(Rb)};
  c.distance = gap;
  return c;
}

const std::vector<ShapeType> kSymmetricTypes = {ShapeType::sphere, ShapeType::capsule,   ShapeType::box,
                                               ShapeType::cylinder, ShapeType::cone,   ShapeType::ellipsoid,
                                               ShapeType::convex};

class AnalyticDistance : public ::testing::TestWithParam<Solver> {};

TEST_P(AnalyticDistance, EveryFamilyMatchesTheExtentGap) {
  Rng rng(1234);
  QueryOptions opt;
  opt.level = QueryLevel::witness;
  opt.solver = GetParam();
  opt.tolerance = 1e-11;
  opt.max_iterations = 1000;
  opt.closed_forms = false;  // exercise GJK on every family, closed forms are tested against it elsewhere
  for (ShapeType ta : kSymmetricTypes)
    for (ShapeType tb : kSymmetricTypes)
      for (int trial = 0; trial < 40; ++trial) {
        const double gap = std::pow(10.0, testing::uniform(rng, -6, -0.5));
        const Config c = make_config(rng, ta, tb, gap);
        const auto r = testing::run_pair(c.a, c.pa, c.b, c.pb, opt);
        SCOPED_TRACE(std::string(to_string(ta)) + "-" + to_string(tb) + " trial " + std::to_string(trial));
        EXPECT_EQ(r.status, Status::converged) << r.distance - c.distance << " gap " << gap << " it " << r.iterations;
        EXPECT_FALSE(r.collide);
        EXPECT_NEAR(r.distance, c.distance, 2e-10);
        const Eigen::Vector3d axis = c.pa.rotation * Eigen::Vector3d::Zero() + (c.pb.translation - c.pa.translation).normalized();
        EXPECT_GT(r.normal.dot(axis), 1.0 - 1e-6);
        EXPECT_LT((r.witness_b - r.witness_a - r.distance * r.normal).norm(), 1e-9);
      }
}

INSTANTIATE_TEST_SUITE_P(Solvers, AnalyticDistance, ::testing::Values(Solver::gjk, Solver::nesterov, Solver::polyak),
                         [](const auto& info) { return std::string(to_string(info.param)); });

}  // namespace
}  // namespace batchcol
