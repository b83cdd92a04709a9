// Analytic derivatives against central finite differences of witness points solved to machine precision.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

namespace batchcol::testing {
namespace {

struct Errors {
  double distance = 0, witness = 0, normal = 0;
  int compared = 0;
};

// Compares every pair whose analytic status is in `statuses`; the finite-difference step is h times the pair's
// distance (translation, in metres; rotation that over the sum of bounding radii): the witness points' derivatives
// vary on the scale of the distance (and of the curvature radii, which are larger here).
Errors compare(const ShapeTable& shapes, const PairBatch& batch, const PairResults& at, double h,
               const std::vector<DerivativeStatus>& statuses, const DerivativeResults* given = nullptr) {
  DerivativeResults computed;
  if (!given) differentiate_results(shapes, batch, at, DerivativeOptions{}, 0, computed);
  const DerivativeResults& d = given ? *given : computed;
  std::vector<double> steps(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i) steps[i] = h * at.distance[i];
  const FiniteDifferences fd = finite_differences(shapes, batch, steps);
  Errors e;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (std::find(statuses.begin(), statuses.end(), d.status[i]) == statuses.end()) continue;
    ++e.compared;
    e.distance = std::max({e.distance, relative_error(d.distance_gradient_a[i], fd.distance_a[i]),
                           relative_error(d.distance_gradient_b[i], fd.distance_b[i])});
    e.witness = std::max({e.witness, relative_error(d.witness_a_wrt_a[i], fd.witness_a_a[i]),
                          relative_error(d.witness_a_wrt_b[i], fd.witness_a_b[i]),
                          relative_error(d.witness_b_wrt_a[i], fd.witness_b_a[i]),
                          relative_error(d.witness_b_wrt_b[i], fd.witness_b_b[i])});
    e.normal = std::max({e.normal, relative_error(d.normal_wrt_a[i], fd.normal_a[i]),
                         relative_error(d.normal_wrt_b[i], fd.normal_b[i])});
  }
  return e;
}

void report(const char* what, const Errors& e) {
  std::cout << what << ": " << e.compared << " pairs, max relative error: distance gradient " << e.distance
            << ", witness Jacobians " << e.witness << ", normal Jacobians " << e.normal << "\n";
}

// Spheres, ellipsoids (strictly convex: Newton-polished reference) in every combination, 25% inflated.
TEST(DerivativesAnalytic, StrictlyConvexPairsMatchFiniteDifferences) {
  Rng rng(18);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::sphere, ShapeType::ellipsoid}, 2000);
  const PairResults exact = exact_witness(shapes, batch);
  // Steps of 1e-4 distance: central differences err by O(1e-8) relative, the reference's rounding (~1e-16 m over
  // steps >= 1e-6 m) by ~1e-10; both far inside the bounds.
  const Errors e = compare(shapes, batch, exact, 1e-4, {DerivativeStatus::smooth});
  report("spheres/ellipsoids", e);
  EXPECT_EQ(e.compared, 2000);
  EXPECT_LE(e.distance, 1e-6);
  EXPECT_LE(e.witness, 1e-5);
  EXPECT_LE(e.normal, 1e-5);
}

// Capsules against spheres and capsules: the closed forms are exact, and a capsule touching along its side is a
// flat of its support map (the segment), taken as infinite curvature along it.
TEST(DerivativesAnalytic, CapsulePairsMatchFiniteDifferences) {
  Rng rng(19);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::sphere, ShapeType::capsule}, 2000);
  const PairResults exact = exact_witness(shapes, batch);
  const Errors e = compare(shapes, batch, exact, 1e-4, {DerivativeStatus::smooth});
  report("spheres/capsules", e);
  EXPECT_GE(e.compared, 1990);  // parallel capsules (non-unique witnesses) are flagged and skipped
  EXPECT_LE(e.distance, 1e-6);
  EXPECT_LE(e.witness, 1e-5);
  EXPECT_LE(e.normal, 1e-5);
}

// Spheres against cylinders and boxes (closed-form reference): a cylinder's rim (curved), side (a flat along the
// axis) and caps (two flats), a box's faces, edges and vertices.
TEST(DerivativesAnalytic, SpheresAgainstCylindersAndBoxesMatchFiniteDifferences) {
  Rng rng(22);
  ShapeTable shapes;
  const PairBatch mixed =
      random_separated_pairs(rng, shapes, {ShapeType::sphere, ShapeType::cylinder, ShapeType::box}, 3000);
  PairBatch batch;  // the sphere-cylinder and sphere-box pairs without inflation on the solid
  for (std::size_t i = 0; i < mixed.size(); ++i) {
    const Shape& a = shapes[mixed.shape_a[i]];
    const Shape& b = shapes[mixed.shape_b[i]];
    const bool sphere_solid = (a.type == ShapeType::sphere) != (b.type == ShapeType::sphere);
    const bool plain =
        (a.type == ShapeType::sphere || a.inflation == 0.0) && (b.type == ShapeType::sphere || b.inflation == 0.0);
    if (sphere_solid && plain) batch.add(mixed.shape_a[i], mixed.pose_a(i), mixed.shape_b[i], mixed.pose_b(i));
  }
  const PairResults exact = exact_witness(shapes, batch);
  const Errors e = compare(shapes, batch, exact, 1e-4, {DerivativeStatus::smooth});
  report("spheres against cylinders/boxes", e);
  EXPECT_GE(e.compared, 500);
  EXPECT_LE(e.distance, 1e-6);
  EXPECT_LE(e.witness, 1e-5);
  EXPECT_LE(e.normal, 1e-5);
}

// Polytopes (boxes, 8-vertex hulls): vertex-face and edge-edge contacts are smooth (a witness slides on the face or
// edge), vertex-vertex ones have zero curvature; GJK terminates exactly on polytopes. Steps of 1e-4 distance keep
// the contact features unchanged.
TEST(DerivativesAnalytic, PolytopePairsMatchFiniteDifferences) {
  Rng rng(20);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::box, ShapeType::convex}, 1000);
  PairResults r;
  collide(shapes, batch, tight_query(), r);
  const Errors e = compare(shapes, batch, r, 1e-4, {DerivativeStatus::smooth, DerivativeStatus::zero_curvature});
  report("boxes/hulls", e);
  EXPECT_GE(e.compared, 900);
  EXPECT_LE(e.distance, 1e-6);
  EXPECT_LE(e.witness, 1e-5);
  EXPECT_LE(e.normal, 1e-5);
}

// The whole pipeline at the default query options (GJK tolerance 1e-8 m): the derivatives are evaluated at GJK's
// witness points, whose error on curved shapes is ~sqrt(2 R tolerance) (a distance error delta moves the witness
// along the surface by sqrt(2 R delta)), so the bounds above hold only at the tight tolerance. Measured here: the
// error at the default tolerance against the same exact reference (2.7e-4 distance gradient, 5.8e-4 witness,
// 7.8e-4 normal Jacobians over 2000 pairs); the bounds are about 3x that.
TEST(DerivativesAnalytic, DefaultToleranceAccuracyIsMeasured) {
  Rng rng(21);
  ShapeTable shapes;
  // Pairs with an exact reference only (the Newton-polished strictly convex ones): on a cylinder or a capsule
  // facing an ellipsoid the tight GJK reference itself is off by ~sqrt(2 R 1e-15) ~ 5e-8 m.
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::sphere, ShapeType::ellipsoid}, 2000);
  const PairResults exact = exact_witness(shapes, batch);
  PairResults r;
  DerivativeResults d;
  differentiate(shapes, batch, QueryOptions{}, DerivativeOptions{}, r, d);
  const Errors e = compare(shapes, batch, exact, 1e-4, {DerivativeStatus::smooth}, &d);
  report("default tolerance, spheres/ellipsoids", e);
  EXPECT_EQ(e.compared, 2000);
  EXPECT_LE(e.distance, 1e-3);
  EXPECT_LE(e.witness, 2e-3);
  EXPECT_LE(e.normal, 3e-3);
}

}  // namespace
}  // namespace batchcol::testing
