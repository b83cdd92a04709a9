// The collide rule under a loose tolerance (issue #16, item 11): `collide` is conservative -- false only when a
// separating plane beyond the margin is certified -- while `distance` is GJK's upper estimate. So a converged pair
// may report collide = 1 with a distance above the margin, by at most the effective tolerance
// max(tolerance, relative_tolerance x distance, precision floor); collide = 0 always comes with a distance above the
// margin. This test checks that documented rule (README "collide and the tolerance", types.hpp QueryOptions::margin)
// on the probe's case and on random near-contact pairs.
#include <batchcol/batchcol.hpp>

#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol {
namespace {

TEST(CollideRule, ProbeCaseBoxEllipsoidFiveMillimetresApartAtToleranceTenCentimetres) {
  ShapeTable shapes;
  shapes.add(Shape::box(0.5, 0.5, 0.5));
  shapes.add(Shape::ellipsoid(0.5, 0.3, 0.2));
  PairBatch batch;
  batch.add(0, Pose::identity(), 1, Pose{Eigen::Vector3d(1.005, 0, 0), Eigen::Quaterniond::Identity()});
  QueryOptions o;
  o.tolerance = 0.1;
  PairResults r;
  collide(shapes, batch, o, r);
  ASSERT_EQ(r.status[0], Status::converged);
  // True distance 0.005: the estimate is within the tolerance of it, and collide may not claim a separation the
  // certificate does not prove.
  EXPECT_LE(std::abs(r.distance[0] - 0.005), 0.1);
  if (r.collide[0]) EXPECT_LE(r.distance[0], o.margin + o.tolerance);
  else EXPECT_GT(r.distance[0], o.margin);
}

TEST(CollideRule, ConvergedPairsFollowTheDocumentedRuleAtLooseTolerances) {
  testing::Rng rng(16);
  ShapeTable shapes;
  for (ShapeType t : testing::bounded_shape_types())
    for (int k = 0; k < 2; ++k) shapes.add(testing::random_shape(rng, t));
  PairBatch batch;
  for (int i = 0; i < 4000; ++i) {
    const auto a = static_cast<std::uint32_t>(rng() % shapes.size()), b = static_cast<std::uint32_t>(rng() % shapes.size());
    const Pose pa{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    // Centres 0.2 to 1.2 apart: overlapping, touching and separated pairs near contact.
    const Pose pb{testing::random_unit_vector(rng) * testing::uniform(rng, 0.2, 1.2), testing::random_rotation(rng)};
    batch.add(a, pa, b, pb);
  }
  int ambiguous = 0;
  for (Precision p : {Precision::float64, Precision::float32})
    for (double tolerance : {1e-3, 3e-2, 0.1})
      for (double margin : {0.0, 0.01}) {
        QueryOptions o;
        o.level = QueryLevel::distance;
        o.precision = p;
        o.tolerance = tolerance;
        o.margin = margin;
        PairResults r;
        collide(shapes, batch, o, r);
        for (std::size_t i = 0; i < r.size(); ++i) {
          if (r.status[i] != Status::converged || std::isnan(r.distance[i])) continue;
          SCOPED_TRACE("pair " + std::to_string(i) + " tolerance " + std::to_string(tolerance));
          if (!r.collide[i]) {
            EXPECT_GT(r.distance[i], margin);
          } else {
            // The float floor (16 eps_f x a few metres) is far below the tolerances used here.
            EXPECT_LE(r.distance[i], margin + tolerance);
            ambiguous += r.distance[i] > margin;
          }
        }
      }
  // The rule is not vacuous: some converged pairs do report collide = 1 above the margin.
  EXPECT_GT(ambiguous, 0);
}

}  // namespace
}  // namespace batchcol
