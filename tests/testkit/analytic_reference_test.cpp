// The testkit's closed-form references (tools/testkit/analytic_reference.hpp) on cases solved by hand, and against
// the engine's GJK/EPA at 1e-12 on random pairs (two independent routes must agree).
#include "testkit/analytic_reference.hpp"
#include "testkit/reference_set.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol::testkit {
namespace {

using Eigen::Vector3d;

TEST(AnalyticReference, PointToSphereBoxCylinderConeByHand) {
  const auto s = point_to_shape(Shape::sphere(0.5), {2, 0, 0});
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s->signed_distance, 1.5);
  EXPECT_TRUE(s->normal.isApprox(Vector3d::UnitX()));
  EXPECT_TRUE(s->point.isApprox(Vector3d(0.5, 0, 0)));

  // Inside a box: the nearest face is +y (0.2 away), the depth is negative.
  const auto b = point_to_shape(Shape::box(1, 0.5, 2), {0.1, 0.3, -0.5});
  ASSERT_TRUE(b);
  EXPECT_NEAR(b->signed_distance, -0.2, 1e-15);
  EXPECT_TRUE(b->normal.isApprox(Vector3d::UnitY()));
  // Outside a box near a corner: the distance is to the corner.
  const auto corner = point_to_shape(Shape::box(1, 1, 1), {2, 2, 1});
  ASSERT_TRUE(corner);
  EXPECT_NEAR(corner->signed_distance, std::sqrt(2.0), 1e-15);

  // Cylinder (radius 1, half length 1): beside the mantle, and above the cap rim.
  const auto c1 = point_to_shape(Shape::cylinder(1, 1), {0, 3, 0.5});
  ASSERT_TRUE(c1);
  EXPECT_NEAR(c1->signed_distance, 2.0, 1e-15);
  const auto c2 = point_to_shape(Shape::cylinder(1, 1), {4, 0, 5});
  ASSERT_TRUE(c2);
  EXPECT_NEAR(c2->signed_distance, 5.0, 1e-14);  // to the rim (1, 0, 1): (3, 4)

  // Cone (radius 1, half length 1, apex at z = +1): a point on the axis above the apex.
  const auto k = point_to_shape(Shape::cone(1, 1), {0, 0, 3});
  ASSERT_TRUE(k);
  EXPECT_NEAR(k->signed_distance, 2.0, 1e-15);
  EXPECT_TRUE(k->point.isApprox(Vector3d(0, 0, 1)));

  // Inflation shifts the distance by the radius.
  const auto inflated = point_to_shape(Shape::box(1, 1, 1).inflated(0.25), {3, 0, 0});
  ASSERT_TRUE(inflated);
  EXPECT_NEAR(inflated->signed_distance, 1.75, 1e-15);

  EXPECT_FALSE(point_to_shape(Shape::ellipsoid(1, 2, 3), {5, 0, 0}));  // no closed form here
}

TEST(AnalyticReference, ClosestPointsOfSegmentsByHand) {
  Vector3d p, q;
  // Crossing segments one above the other: closest points are the crossing point and the one above it.
  closest_points_of_segments({-1, 0, 0}, {1, 0, 0}, {0, -1, 2}, {0, 1, 2}, p, q);
  EXPECT_TRUE(p.isApprox(Vector3d(0, 0, 0)));
  EXPECT_TRUE(q.isApprox(Vector3d(0, 0, 2)));
  // Parallel, offset along their direction: an end point of each.
  closest_points_of_segments({0, 0, 0}, {1, 0, 0}, {3, 1, 0}, {5, 1, 0}, p, q);
  EXPECT_TRUE(p.isApprox(Vector3d(1, 0, 0)));
  EXPECT_TRUE(q.isApprox(Vector3d(3, 1, 0)));
  // An end point against the inside of the other segment.
  closest_points_of_segments({0, 0, 0}, {0, 0, 1}, {-1, 2, 3}, {1, 2, 3}, p, q);
  EXPECT_TRUE(p.isApprox(Vector3d(0, 0, 1)));
  EXPECT_TRUE(q.isApprox(Vector3d(0, 2, 3)));
}

TEST(AnalyticReference, CoversTheTypePairsItClaims) {
  EXPECT_TRUE(has_closed_form(ShapeType::sphere, ShapeType::cone));
  EXPECT_TRUE(has_closed_form(ShapeType::box, ShapeType::sphere));
  EXPECT_TRUE(has_closed_form(ShapeType::capsule, ShapeType::capsule));
  EXPECT_FALSE(has_closed_form(ShapeType::box, ShapeType::box));
  EXPECT_FALSE(analytic_reference(Shape::box(1, 1, 1), Pose::identity(), Shape::box(1, 1, 1), Pose::identity()));
  // Capsule against capsule, both along z and 1 m apart in y: distance 1 - 2 * 0.1.
  const auto cc = analytic_reference(Shape::capsule(0.1, 0.5), Pose::identity(), Shape::capsule(0.1, 0.5),
                                     Pose::from_translation({0, 1, 0}));
  ASSERT_TRUE(cc);
  EXPECT_NEAR(cc->distance, 0.8, 1e-15);
  EXPECT_TRUE(cc->normal.isApprox(Vector3d::UnitY()));
}

// The analytic references and the engine's certified numeric reference (GJK/EPA in double at 1e-12) are computed
// by unrelated code; on every closed-form case and regime they must agree far below the accuracy being measured.
TEST(AnalyticReference, AgreesWithTheNumericReferenceOnBenchPairs) {
  for (const char* spec : {"sphere-box", "sphere-cylinder", "sphere-cone", "capsule-capsule", "sphere-capsule"}) {
    for (Regime regime : {Regime::close, Regime::overlap, Regime::distant}) {
      const BenchPairs pairs = make_bench_pairs(parse_bench_cases(spec)[0], regime, 64, 9, 2);
      const ReferenceSet set = compute_references(pairs, 2);
      EXPECT_EQ(set.kind, "analytic") << spec;
      EXPECT_TRUE(set.unique_witnesses) << spec;
      EXPECT_LT(set.analytic_vs_numeric, 1e-9) << spec << " " << to_string(regime);
      for (std::size_t i = 0; i < set.pairs.size(); ++i) {
        ASSERT_TRUE(set.pairs[i].analytic && set.pairs[i].certified);
        EXPECT_NEAR(set.pairs[i].normal.norm(), 1.0, 1e-12);
        // The witnesses are `distance` apart along the normal.
        const Vector3d gap = set.pairs[i].witness_b - set.pairs[i].witness_a;
        EXPECT_NEAR(gap.dot(set.pairs[i].normal), set.pairs[i].distance, 1e-12) << spec << " pair " << i;
      }
    }
  }
}

}  // namespace
}  // namespace batchcol::testkit
