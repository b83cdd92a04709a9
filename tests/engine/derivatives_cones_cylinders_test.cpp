// Analytic derivatives of cones and of cylinders against non-spheres, against central finite differences.
//
// There is no machine-precision reference here (no closed form, no Newton polish: the support maps jump on the
// caps, sides and the other shapes' faces), so the reference witness points are GJK's at the precision floor
// (tight_query(), ~1e-15 m duality gap). On a curved contact that leaves the witness points off by up to
// ~sqrt(2 R 1e-15) ~ 5e-8 m (R <= 0.4 m here). Steps of 3e-3 x distance keep that noise below ~5e-8 / 3e-4 / 2
// ~ 1e-4 of an O(1) entry for pairs 0.1 m apart (the closest pairs, 2% of the radii sum, get up to ~10x more), and the
// central differences' truncation error (O(h^2) relative to the curvature radii, >= 0.05 m) below ~1e-4. Hence
// bounds of 1e-3 here, not the 1e-5 of the exact references in derivatives_analytic_test.cpp: a wrong formula
// (a missing curvature term, a sign) shows as an O(1) error. Steps that cross a feature boundary (rim to side,
// edge to face) differentiate two different formulas; the few pairs within a step of one are counted as
// outliers; see expect_measured() for what is asserted.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace batchcol::testing {
namespace {

struct Errors {
  std::vector<double> per_pair;  // max over the distance gradient, witness and normal Jacobians
  double distance = 0, witness = 0, normal = 0;  // max over the pairs within the bound
  double distance_all = 0;                       // the distance gradient's max over every compared pair
  int compared = 0, flagged = 0, outliers = 0;
};

std::string local(const ShapeTable& shapes, const PairBatch& batch, const PairResults& at, std::size_t i, bool a) {
  const Pose p = a ? batch.pose_a(i) : batch.pose_b(i);
  const Eigen::Vector3d w = a ? at.witness_a[i] : at.witness_b[i];
  const Eigen::Vector3d l = p.rotation.conjugate() * (w - p.translation);
  const Shape& s = shapes[a ? batch.shape_a[i] : batch.shape_b[i]];
  char buf[160];
  std::snprintf(buf, sizeof buf, "(%.4f %.4f %.4f | size %.3f %.3f %.3f infl %.3f)", l.x(), l.y(), l.z(), s.size.x(),
                s.size.y(), s.size.z(), s.inflation);
  return buf;
}

Errors compare(const ShapeTable& shapes, const PairBatch& batch, const std::vector<DerivativeStatus>& statuses,
               double bound) {
  PairResults at;
  collide(shapes, batch, tight_query(), at);
  DerivativeResults d;
  differentiate_results(shapes, batch, at, DerivativeOptions{}, 0, d);
  std::vector<double> steps(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i) steps[i] = 3e-3 * at.distance[i];
  const FiniteDifferences fd = finite_differences(shapes, batch, steps);
  Errors e;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (d.status[i] == DerivativeStatus::nonsmooth) ++e.flagged;
    if (std::find(statuses.begin(), statuses.end(), d.status[i]) == statuses.end()) continue;
    const double distance = std::max(relative_error(d.distance_gradient_a[i], fd.distance_a[i]),
                                     relative_error(d.distance_gradient_b[i], fd.distance_b[i]));
    const double witness = std::max({relative_error(d.witness_a_wrt_a[i], fd.witness_a_a[i]),
                                     relative_error(d.witness_a_wrt_b[i], fd.witness_a_b[i]),
                                     relative_error(d.witness_b_wrt_a[i], fd.witness_b_a[i]),
                                     relative_error(d.witness_b_wrt_b[i], fd.witness_b_b[i])});
    const double normal = std::max(relative_error(d.normal_wrt_a[i], fd.normal_a[i]),
                                   relative_error(d.normal_wrt_b[i], fd.normal_b[i]));
    ++e.compared;
    e.distance_all = std::max(e.distance_all, distance);
    e.per_pair.push_back(std::max({distance, witness, normal}));
    if (!(e.per_pair.back() <= bound)) {
      if (std::getenv("BATCHCOL_PRINT_OUTLIERS"))  // the pairs to study for the open question below
        std::printf("outlier %s-%s status %s: d %.2e w %.2e n %.2e dist %.3e pa %s pb %s\n",
                    to_string(shapes[batch.shape_a[i]].type), to_string(shapes[batch.shape_b[i]].type),
                    to_string(d.status[i]), distance, witness, normal, at.distance[i],
                    local(shapes, batch, at, i, true).c_str(), local(shapes, batch, at, i, false).c_str());
      ++e.outliers;
      continue;
    }
    e.distance = std::max(e.distance, distance);
    e.witness = std::max(e.witness, witness);
    e.normal = std::max(e.normal, normal);
  }
  std::sort(e.per_pair.begin(), e.per_pair.end());
  return e;
}

// What holds (measured: see the README's derivatives section): the typical pair agrees to ~1e-5 (median), 90%
// to 5e-4, but ~5% of the pairs disagree in a Jacobian by 1e-2 to 1 at every step tried (1e-2, 3e-3, 1e-3,
// 3e-4 x distance), a few even in the distance gradient (up to 3e-2), which the envelope theorem gives from the
// witness points and normal alone - so at least those pairs point at the tight GJK reference (or the nominal
// query) rather than at the curvature formulas; not resolved (issue #18 leaves it open; run with
// BATCHCOL_PRINT_OUTLIERS=1 to list them). These bounds catch a formula wrong for a whole contact type, which
// would move the median to O(1).
void expect_measured(const Errors& e) {
  ASSERT_FALSE(e.per_pair.empty());
  EXPECT_LE(e.per_pair[e.per_pair.size() / 2], 1e-4);
  EXPECT_LE(e.per_pair[e.per_pair.size() * 9 / 10], 2e-3);
  EXPECT_LE(e.outliers, e.compared * 8 / 100);
}

void report(const char* what, const Errors& e) {
  const auto quantile = [&](double q) {
    return e.per_pair.empty() ? 0.0 : e.per_pair[static_cast<std::size_t>(q * double(e.per_pair.size() - 1))];
  };
  std::printf("%s: %d pairs compared (%d flagged nonsmooth, %d outliers), max relative error within the bound: "
              "distance gradient %.2e, witness Jacobians %.2e, normal Jacobians %.2e; per-pair median %.2e, "
              "90%% %.2e, 99%% %.2e; distance gradient over all pairs %.2e\n",
              what, e.compared, e.flagged, e.outliers, e.distance, e.witness, e.normal, quantile(0.5),
              quantile(0.9), quantile(0.99), e.distance_all);
}

// Cylinders against ellipsoids, capsules, boxes, hulls and cylinders: rim (curved), side (a flat along the axis)
// and cap (two flats) contacts against curved, segment and polytope features.
TEST(DerivativesCylinders, AgainstNonSpheresMatchFiniteDifferences) {
  Rng rng(23);
  ShapeTable shapes;
  const PairBatch mixed = random_separated_pairs(
      rng, shapes, {ShapeType::cylinder, ShapeType::ellipsoid, ShapeType::capsule, ShapeType::box, ShapeType::convex},
      4000);
  PairBatch batch;  // the pairs with a cylinder and no sphere
  for (std::size_t i = 0; i < mixed.size(); ++i) {
    const ShapeType a = shapes[mixed.shape_a[i]].type, b = shapes[mixed.shape_b[i]].type;
    if (a == ShapeType::cylinder || b == ShapeType::cylinder)
      batch.add(mixed.shape_a[i], mixed.pose_a(i), mixed.shape_b[i], mixed.pose_b(i));
  }
  const double bound = 1e-3;
  const Errors e = compare(shapes, batch, {DerivativeStatus::smooth, DerivativeStatus::zero_curvature}, bound);
  report("cylinders against non-spheres", e);
  EXPECT_GE(e.compared, 1200);
  expect_measured(e);
}

// Cones against spheres, ellipsoids, boxes and cones: the rim (curved), the base (two flats) and the apex (a
// vertex) are compared; a witness on the side is flagged nonsmooth (its values use the rim's curvature) and
// skipped, but must occur and be flagged.
TEST(DerivativesCones, RimBaseAndApexMatchFiniteDifferencesSideIsFlagged) {
  Rng rng(24);
  ShapeTable shapes;
  const PairBatch mixed = random_separated_pairs(
      rng, shapes, {ShapeType::cone, ShapeType::sphere, ShapeType::ellipsoid, ShapeType::box}, 4000);
  PairBatch batch;
  for (std::size_t i = 0; i < mixed.size(); ++i) {
    const ShapeType a = shapes[mixed.shape_a[i]].type, b = shapes[mixed.shape_b[i]].type;
    if (a == ShapeType::cone || b == ShapeType::cone)
      batch.add(mixed.shape_a[i], mixed.pose_a(i), mixed.shape_b[i], mixed.pose_b(i));
  }
  const double bound = 1e-3;
  const Errors e = compare(shapes, batch, {DerivativeStatus::smooth, DerivativeStatus::zero_curvature}, bound);
  report("cones", e);
  EXPECT_GE(e.compared, 1000);
  EXPECT_GE(e.flagged, 10);
  expect_measured(e);
}

}  // namespace
}  // namespace batchcol::testing
