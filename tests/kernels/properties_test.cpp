// Properties every answer must have, on random pairs of every bounded type: witness points on the surfaces with
// the normal as their normalised difference (KKT), symmetry under (a, b) -> (b, a), invariance under a common
// rigid transform, agreement of the three solvers, and float within its error budget of double.
#include "support/generators.hpp"

#include <gtest/gtest.h>

namespace batchcol {
namespace {

using testing::Rng;

struct RandomPair {
  Shape a, b;
  Pose pa, pb;
};

RandomPair random_pair(Rng& rng, ShapeType ta, ShapeType tb) {
  RandomPair p{testing::random_shape(rng, ta), testing::random_shape(rng, tb), {}, {}};
  if (rng() % 4 == 0) p.b = p.b.inflated(testing::uniform(rng, 0.0, 0.02));
  p.pa = {testing::random_vector(rng), testing::random_rotation(rng)};
  p.pb = {p.pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.5),
          testing::random_rotation(rng)};
  return p;
}

QueryOptions tight(Solver solver = Solver::nesterov) {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.solver = solver;
  o.tolerance = 1e-11;
  o.max_iterations = 500;
  o.epa_max_iterations = 1000;
  return o;
}

/// Distance from point p (world) to the shape's surface, signed through the support function: the witness point
/// of a shape must maximise <., n> over it, i.e. <p, n> = h(n) (the shape's extent along n).
double support_gap(const Shape& s, const Pose& pose, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  const Eigen::Vector3d local_n = pose.rotation.inverse() * n;
  return testing::extent(s, local_n) + n.dot(pose.translation) - n.dot(p);
}

class Properties : public ::testing::TestWithParam<ShapeType> {};

TEST_P(Properties, KktSwapInvarianceSolversAndFloat) {
  Rng rng(1000 + static_cast<int>(GetParam()));
  int separated = 0;
  for (ShapeType tb : testing::bounded_shape_types()) {
    for (int trial = 0; trial < 60; ++trial) {
      const RandomPair p = random_pair(rng, GetParam(), tb);
      SCOPED_TRACE(std::string(to_string(GetParam())) + "-" + to_string(tb) + " trial " + std::to_string(trial));
      const auto r = testing::run_pair(p.a, p.pa, p.b, p.pb, tight());
      ASSERT_EQ(r.status, Status::converged);
      ASSERT_TRUE(std::isfinite(r.distance));
      // Depth accuracy is EPA's tolerance on curved shapes, distance accuracy GJK's.
      const double tol = r.distance < 0 ? 1e-8 : 1e-9;
      if (r.distance > 0) {
        ++separated;
        // KKT: witness a maximises <., n> on A; witness b maximises <., -n> on B.
        EXPECT_NEAR(support_gap(p.a, p.pa, r.witness_a, r.normal), 0.0, tol);
        EXPECT_NEAR(support_gap(p.b, p.pb, r.witness_b, -r.normal), 0.0, tol);
      }
      EXPECT_LT((r.witness_b - r.witness_a - r.distance * r.normal).norm(), 1e-9);
      EXPECT_EQ(r.collide, r.distance <= 0);

      const auto swapped = testing::run_pair(p.b, p.pb, p.a, p.pa, tight());
      EXPECT_NEAR(swapped.distance, r.distance, tol);
      if (std::abs(r.distance) > 1e-6 && tb != ShapeType::triangle && GetParam() != ShapeType::triangle) {
        EXPECT_GT(swapped.normal.dot(-r.normal), 1 - 1e-6);
      }

      const Eigen::Quaterniond Q = testing::random_rotation(rng);
      const Eigen::Vector3d T = testing::random_vector(rng) * 50;
      const auto moved = testing::run_pair(p.a, Pose{Q * p.pa.translation + T, Q * p.pa.rotation}, p.b,
                                           Pose{Q * p.pb.translation + T, Q * p.pb.rotation}, tight());
      EXPECT_NEAR(moved.distance, r.distance, tol);

      for (Solver s : {Solver::gjk, Solver::polyak}) {
        const auto other = testing::run_pair(p.a, p.pa, p.b, p.pb, tight(s));
        EXPECT_EQ(other.status, Status::converged);
        EXPECT_NEAR(other.distance, r.distance, tol) << to_string(s);
      }

      QueryOptions f = tight();
      f.precision = Precision::float32;
      f.tolerance = 1e-6;
      const auto single = testing::run_pair(p.a, p.pa, p.b, p.pb, f);
      EXPECT_NE(single.status, Status::invalid_input);
      // Float: relative 1e-5 of the problem size (0.5 m) plus the float tolerance floor.
      EXPECT_NEAR(single.distance, r.distance, 1e-5) << "float";
    }
  }
  EXPECT_GT(separated, 100);
}

INSTANTIATE_TEST_SUITE_P(EveryType, Properties, ::testing::ValuesIn(testing::bounded_shape_types()),
                         [](const auto& info) { return std::string(to_string(info.param)); });

}  // namespace
}  // namespace batchcol
