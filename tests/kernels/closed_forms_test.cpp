// Every closed form against GJK + EPA on the same random pairs (closed_forms = false), and halfspaces against
// the extent formula min_{y in B} <n, y> = <n, t_b> - h_B(-R_b^T n).
#include "support/generators.hpp"

#include <gtest/gtest.h>

namespace batchcol {
namespace {

using testing::Rng;

struct Family {
  ShapeType a, b;
};

class ClosedFormVsGjk : public ::testing::TestWithParam<Family> {};

TEST_P(ClosedFormVsGjk, AgreeOnRandomPairs) {
  const Family f = GetParam();
  Rng rng(99 + static_cast<int>(f.a) * 10 + static_cast<int>(f.b));
  QueryOptions closed, general;
  closed.level = general.level = QueryLevel::penetration;
  closed.tolerance = general.tolerance = 1e-12;
  general.closed_forms = false;
  general.max_iterations = 1000;
  general.epa_max_iterations = 1000;
  int overlapping = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Shape a = testing::random_shape(rng, f.a), b = testing::random_shape(rng, f.b);
    if (trial % 4 == 0) a = a.inflated(testing::uniform(rng, 0, 0.03));
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.5),
                  testing::random_rotation(rng)};
    const auto c = testing::run_pair(a, pa, b, pb, closed);
    const auto g = testing::run_pair(a, pa, b, pb, general);
    SCOPED_TRACE("trial " + std::to_string(trial) + " distance " + std::to_string(c.distance));
    ASSERT_EQ(c.status, Status::converged);
    ASSERT_EQ(g.status, Status::converged);
    EXPECT_EQ(c.collide, g.collide);
    overlapping += c.distance < 0;
    // EPA on a polytope core is exact up to its tolerance; the closed form is exact.
    EXPECT_NEAR(c.distance, g.distance, c.distance < 0 ? 1e-9 : 1e-10);
    EXPECT_LT((c.witness_b - c.witness_a - c.distance * c.normal).norm(), 1e-12);
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    // The normal is unique unless the cores touch or cross (then any separating direction is valid).
    if (c.distance > 1e-6) {
      EXPECT_GT(c.normal.dot(g.normal), 1 - 1e-8);
      EXPECT_LT((c.witness_a - g.witness_a).norm(), 1e-6);
    }
  }
  EXPECT_GT(overlapping, 200);  // both regimes are exercised
}

INSTANTIATE_TEST_SUITE_P(Families, ClosedFormVsGjk,
                         ::testing::Values(Family{ShapeType::sphere, ShapeType::sphere},
                                           Family{ShapeType::sphere, ShapeType::capsule},
                                           Family{ShapeType::capsule, ShapeType::sphere},
                                           Family{ShapeType::capsule, ShapeType::capsule},
                                           Family{ShapeType::sphere, ShapeType::box},
                                           Family{ShapeType::box, ShapeType::sphere}),
                         [](const auto& info) {
                           return std::string(to_string(info.param.a)) + "_" + to_string(info.param.b);
                         });

TEST(ClosedForms, BoxBoxSeparatingAxisMatchesGjk) {
  Rng rng(5);
  QueryOptions sat, general;
  sat.level = general.level = QueryLevel::boolean;
  general.closed_forms = false;
  QueryOptions dist = general;
  dist.level = QueryLevel::witness;
  dist.tolerance = 1e-12;
  int colliding = 0, compared = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const Shape a = testing::random_shape(rng, ShapeType::box), b = testing::random_shape(rng, ShapeType::box);
    const Pose pa{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    const Pose pb{testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.5), testing::random_rotation(rng)};
    const auto d = testing::run_pair(a, pa, b, pb, dist);
    if (!d.collide && d.distance < 1e-9) continue;  // within rounding of touching: either answer is right
    ++compared;
    const bool s = testing::run_pair(a, pa, b, pb, sat).collide;
    EXPECT_EQ(s, testing::run_pair(a, pa, b, pb, general).collide) << trial;
    EXPECT_EQ(s, d.collide) << trial;
    colliding += s;
  }
  EXPECT_GT(colliding, 500);
  EXPECT_GT(compared - colliding, 500);
}

TEST(ClosedForms, HalfspaceAgainstEveryShapeMatchesExtentFormula) {
  Rng rng(17);
  QueryOptions opt;
  opt.level = QueryLevel::penetration;
  for (ShapeType t : testing::bounded_shape_types())
    for (int trial = 0; trial < 500; ++trial) {
      const Eigen::Vector3d n = testing::random_unit_vector(rng);
      const double offset = testing::uniform(rng, -0.2, 0.2);
      const Shape h = Shape::halfspace(n, offset).inflated(trial % 3 == 0 ? 0.01 : 0.0);
      const Shape b = testing::random_shape(rng, t);
      const Pose pb{testing::random_vector(rng) * 0.5, testing::random_rotation(rng)};
      const double expected =
          n.dot(pb.translation) - testing::extent(b, pb.rotation.inverse() * -n) - offset - h.inflation;
      for (bool swap : {false, true}) {
        const auto r = swap ? testing::run_pair(b, pb, h, Pose{}, opt) : testing::run_pair(h, Pose{}, b, pb, opt);
        SCOPED_TRACE(std::string(to_string(t)) + " trial " + std::to_string(trial) + (swap ? " swapped" : ""));
        ASSERT_EQ(r.status, Status::converged);
        EXPECT_NEAR(r.distance, expected, 1e-12);
        EXPECT_EQ(r.collide, expected <= 0);
        EXPECT_LT((r.normal - (swap ? -n : n)).norm(), 1e-12);
        EXPECT_LT((r.witness_b - r.witness_a - r.distance * r.normal).norm(), 1e-12);
      }
    }
}

TEST(ClosedForms, AntiparallelHalfspacesGiveTheSlabGap) {
  const Shape floor = Shape::halfspace({0, 0, 1}, 0.0);      // z <= 0
  const Shape ceiling = Shape::halfspace({0, 0, -1}, -1.5);  // z >= 1.5
  QueryOptions opt;
  opt.level = QueryLevel::penetration;
  const auto r = testing::run_pair(floor, Pose{}, ceiling, Pose{}, opt);
  EXPECT_NEAR(r.distance, 1.5, 1e-15);
  EXPECT_FALSE(r.collide);
  const auto tilted = testing::run_pair(
      floor, Pose{}, Shape::halfspace({0, 1, -1}, -1.5), Pose{}, opt);
  EXPECT_TRUE(tilted.collide);
  EXPECT_EQ(tilted.distance, -std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace batchcol
