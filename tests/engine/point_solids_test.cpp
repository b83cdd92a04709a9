// Sphere against cylinder, cone and box in closed form (kernels/simd/wide_point_solids.inl): exact answers on hand-made
// placements, agreement with GJK / EPA (closed forms off, tolerance 1e-12) on random pairs in every regime and both
// orders, the same bits on every instruction set, and invalid lanes left to the scalar path.
#include "batchcol/batchcol.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace batchcol {
namespace {

using testing::Rng;

struct Case {
  Eigen::Vector3d centre;  // the sphere's centre in the solid's frame
  double distance;         // signed
  Eigen::Vector3d normal;  // outward from the solid at its closest point
};

/// One pair per case, the solid at a random pose, in both orders; checks distance, normal and witness points.
void check_cases(const Shape& solid, double sphere_radius, const std::vector<Case>& cases, const std::string& what) {
  Rng rng(7);
  ShapeTable table;
  const std::uint32_t s = table.add(Shape::sphere(sphere_radius)), c = table.add(solid);
  for (const bool sphere_a : {false, true}) {
    PairBatch batch;
    std::vector<Pose> solid_poses;
    for (const Case& k : cases) {
      const Pose ps{testing::uniform(rng, -1.0, 1.0) * Eigen::Vector3d::Ones(), testing::random_rotation(rng)};
      const Pose pc{ps.rotation * k.centre + ps.translation, testing::random_rotation(rng)};
      // pc is the sphere's pose: its centre is where the case puts it in the solid's frame (ps is the solid's).
      if (sphere_a) batch.add(s, pc, c, ps);
      else batch.add(c, ps, s, pc);
      solid_poses.push_back(ps);
    }
    QueryOptions o;
    o.level = QueryLevel::penetration;
    PairResults r;
    collide(table, batch, o, r);
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const std::string at = what + " case " + std::to_string(i) + (sphere_a ? " (sphere A)" : " (solid A)");
      ASSERT_EQ(r.status[i], Status::converged) << at;
      EXPECT_EQ(r.iterations[i], 0) << at << ": not the closed form";
      EXPECT_NEAR(r.distance[i], cases[i].distance, 1e-14) << at;
      const Eigen::Vector3d n_out = solid_poses[i].rotation * cases[i].normal;
      const Eigen::Vector3d n = sphere_a ? Eigen::Vector3d(-n_out) : n_out;
      // The radial direction is the centre's offset from the axis over its length: rounding of the poses (1e-16 m)
      // over 1e-3 m for the case next to the axis.
      EXPECT_LT((r.normal[i] - n).norm(), 1e-12) << at;
      // witness_a - witness_b = -distance * normal (from A to B), the sphere's witness on its surface.
      EXPECT_LT((r.witness_a[i] - r.witness_b[i] + r.distance[i] * r.normal[i]).norm(), 1e-14) << at;
      const Eigen::Vector3d centre = sphere_a ? batch.pose_a(i).translation : batch.pose_b(i).translation;
      const Eigen::Vector3d on_sphere = sphere_a ? r.witness_a[i] : r.witness_b[i];
      EXPECT_NEAR((on_sphere - centre).norm(), sphere_radius, 1e-14) << at;
      EXPECT_EQ(r.collide[i], cases[i].distance <= 0.0 ? 1 : 0) << at;
    }
  }
}

TEST(PointSolids, CylinderPlacementsHaveTheirExactAnswers) {
  const double r = 0.25;  // sphere radius; cylinder radius 1, half length 2
  check_cases(Shape::cylinder(1.0, 2.0), r,
              {{{3.0, 0.0, 0.0}, 2.0 - r, {1, 0, 0}},                               // beside the side
               {{0.0, 0.0, 5.0}, 3.0 - r, {0, 0, 1}},                               // above the cap
               {{0.3, -0.4, -4.0}, 2.0 - r, {0, 0, -1}},                            // below the other cap
               {{2.0, 0.0, 3.0}, std::sqrt(2.0) - r, {std::sqrt(0.5), 0, std::sqrt(0.5)}},  // beyond the rim
               {{0.0, 0.8, 0.0}, -0.2 - r, {0, 1, 0}},                              // inside, nearer the side
               {{0.1, 0.0, 1.9}, -0.1 - r, {0, 0, 1}},                              // inside, nearer the cap
               {{1e-3, 0.0, 0.5}, -0.999 - r, {1, 0, 0}}},                          // next to the axis
              "cylinder");
}

TEST(PointSolids, ConePlacementsHaveTheirExactAnswers) {
  const double r = 0.25;  // cone radius 1, half length 1: apex (0, 0, 1), base z = -1; slant normal (2, 1) / sqrt 5
  const double s5 = std::sqrt(5.0);
  const Eigen::Vector3d slant_n(2.0 / s5, 0.0, 1.0 / s5);
  check_cases(Shape::cone(1.0, 1.0), r,
              {{{0.0, 0.0, 3.0}, 2.0 - r, {0, 0, 1}},                            // above the apex
               {{0.2, 0.1, -1.5}, 0.5 - r, {0, 0, -1}},                          // below the base
               {Eigen::Vector3d(0.5, 0, 0) + 1.5 * slant_n, 1.5 - r, slant_n},  // beyond the slant, mid edge
               {{2.0, 0.0, -2.0}, std::sqrt(2.0) - r, {std::sqrt(0.5), 0, -std::sqrt(0.5)}},  // beyond the rim
               {{0.0, 0.0, -0.9}, -0.1 - r, {0, 0, -1}},                         // inside, nearer the base
               {Eigen::Vector3d(0.5, 0, 0) - 0.05 * slant_n, -0.05 - r, slant_n}},  // inside, nearer the slant
              "cone");
}

TEST(PointSolids, BoxPlacementsHaveTheirExactAnswers) {
  const double r = 0.25, s3 = std::sqrt(3.0);  // sphere radius; box half extents (1, 2, 3)
  check_cases(Shape::box(1.0, 2.0, 3.0), r,
              {{{3.0, 0.5, -1.0}, 2.0 - r, {1, 0, 0}},                                   // beside the +x face
               {{0.2, -0.3, -5.0}, 2.0 - r, {0, 0, -1}},                                 // below the -z face
               {{2.0, 3.0, 0.0}, std::sqrt(2.0) - r, {std::sqrt(0.5), std::sqrt(0.5), 0}},  // beyond an edge
               {{-2.0, -3.0, 4.0}, s3 - r, {-1 / s3, -1 / s3, 1 / s3}},                  // beyond a vertex
               {{0.9, 0.0, 0.0}, -0.1 - r, {1, 0, 0}},                                   // inside, nearer +x
               {{0.0, -1.7, 0.5}, -0.3 - r, {0, -1, 0}},                                 // inside, nearer -y
               {{0.0, 0.0, 2.95}, -0.05 - r, {0, 0, 1}},                                 // inside, nearer +z
               {{-0.6, 1.5, 0.0}, -0.4 - r, {-1, 0, 0}}},                                // inside, nearer -x
              "box");
}

/// A centre at the same depth under two or three faces takes x before y before z (sphere_box()'s order). Identity
/// poses: check_cases()'s random poses would break the ties by rounding.
TEST(PointSolids, BoxDepthTiesTakeXThenYThenZ) {
  const double r = 0.25;
  struct Tie {
    Eigen::Vector3d half, centre, normal;
    double depth;
  };
  const Tie ties[] = {{{1, 2, 3}, {0, 1, 0}, {1, 0, 0}, 1.0},     // x and y
                      {{1, 2, 3}, {0, 0, -2}, {1, 0, 0}, 1.0},    // x and z
                      {{2, 1, 1}, {0, 0, 0}, {0, 1, 0}, 1.0},     // y and z
                      {{1, 1, 1}, {0, 0, 0}, {1, 0, 0}, 1.0},     // all three, the box's centre
                      {{1, 1, 1}, {-0.5, 0.5, 0}, {-1, 0, 0}, 0.5}};  // x and y, negative x
  for (const Tie& k : ties) {
    ShapeTable table;
    const std::uint32_t box = table.add(Shape::box(k.half)), sphere = table.add(Shape::sphere(r));
    PairBatch batch;
    batch.add(box, Pose{}, sphere, Pose{k.centre, Eigen::Quaterniond::Identity()});
    QueryOptions o;
    o.level = QueryLevel::penetration;
    PairResults res;
    collide(table, batch, o, res);
    ASSERT_EQ(res.status[0], Status::converged);
    EXPECT_EQ(res.distance[0], -k.depth - r) << k.centre.transpose();
    EXPECT_EQ(res.normal[0], k.normal) << k.centre.transpose();
  }
}

/// Random sphere-cylinder / sphere-cone / sphere-box pairs (sizes 2-40 cm, inflated or not, both orders, distant to deeply
/// overlapping) against GJK and EPA with the closed forms off at tolerance 1e-12.
TEST(PointSolids, AgreeWithGjkAndEpaOnRandomPairs) {
  Rng rng(11);
  ShapeTable table;
  std::vector<std::uint32_t> spheres, solids;
  const ShapeType kinds[3] = {ShapeType::cylinder, ShapeType::cone, ShapeType::box};
  for (int i = 0; i < 60; ++i) {
    Shape sphere = testing::random_shape(rng, ShapeType::sphere);
    Shape solid = testing::random_shape(rng, kinds[i % 3]);
    if (i % 4 == 0) sphere = sphere.inflated(0.01);
    if (i % 5 < 2) solid = solid.inflated(0.02);
    spheres.push_back(table.add(sphere));
    solids.push_back(table.add(solid));
  }
  PairBatch batch;
  for (int i = 0; i < 6000; ++i) {
    const std::uint32_t a = spheres[rng() % spheres.size()], b = solids[rng() % solids.size()];
    const Pose pa{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    const Pose pb{testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.8), testing::random_rotation(rng)};
    if (i % 2) batch.add(a, pa, b, pb);
    else batch.add(b, pb, a, pa);
  }
  QueryOptions closed, reference;
  closed.level = reference.level = QueryLevel::penetration;
  reference.closed_forms = false;
  reference.solver = Solver::gjk;
  reference.tolerance = 1e-12;
  reference.epa_max_iterations = 1000;
  PairResults got, want;
  collide(table, batch, closed, got);
  collide(table, batch, reference, want);
  std::size_t inside = 0, compared = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    ASSERT_EQ(got.status[i], Status::converged) << i;
    if (want.status[i] != Status::converged) continue;  // the reference itself did not certify this pair
    ++compared;
    const double err = std::abs(got.distance[i] - want.distance[i]);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-9) << "pair " << i << ": " << got.distance[i] << " vs " << want.distance[i];
    if (std::abs(want.distance[i]) > 1e-6) {
      EXPECT_EQ(got.collide[i], want.collide[i]) << i;
      EXPECT_LT((got.normal[i] - want.normal[i]).norm(), 1e-5) << i;
      EXPECT_LT((got.witness_a[i] - want.witness_a[i]).norm(), 1e-5) << i;
      EXPECT_LT((got.witness_b[i] - want.witness_b[i]).norm(), 1e-5) << i;
    }
    inside += got.distance[i] < 0.0;
  }
  EXPECT_GT(compared, 5850u);
  EXPECT_GT(inside, 750u);  // the overlapping regime is exercised
  EXPECT_GT(batch.size() - inside, 750u);
  RecordProperty("worst_distance_error", std::to_string(worst));
}

TEST(PointSolids, EveryInstructionSetGivesTheSameBitsAndInvalidPairsAreRefused) {
  Rng rng(12);
  ShapeTable table;
  const std::uint32_t s = table.add(Shape::sphere(0.1)), cyl = table.add(Shape::cylinder(0.2, 0.3)),
                      cone = table.add(Shape::cone(0.25, 0.2).inflated(0.01)),
                      box = table.add(Shape::box(0.1, 0.2, 0.15).inflated(0.005));
  PairBatch batch;
  for (int i = 0; i < 1000; ++i) {
    const Pose pa{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    Pose pb{testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.6), testing::random_rotation(rng)};
    if (i % 97 == 0) pb.rotation.coeffs() *= 1.1;  // not a unit quaternion: invalid_input
    const std::uint32_t solid = i % 3 == 0 ? cone : i % 3 == 1 ? cyl : box;
    if (i % 2) batch.add(s, pa, solid, pb);
    else batch.add(solid, pb, s, pa);
  }
  for (const QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
    QueryOptions o;
    o.level = level;
    o.isa = InstructionSet::scalar;
    PairResults want;
    collide(table, batch, o, want);
    for (std::size_t i = 0; i < batch.size(); ++i)
      EXPECT_EQ(want.status[i] == Status::invalid_input, i % 97 == 0) << i;
    for (const InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
      if (!kernels::simd::cpu_has(isa)) continue;
      o.isa = isa;
      PairResults got;
      collide(table, batch, o, got);
      testing::expect_same_results(want, got, std::string(to_string(isa)) + " " + to_string(level));
    }
  }
}

}  // namespace
}  // namespace batchcol
