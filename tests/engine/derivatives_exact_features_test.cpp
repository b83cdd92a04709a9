// Analytic derivatives against central finite differences of witness points solved to machine precision on their
// features (feature_witness(): each witness locked on its face, edge, vertex, segment, cap, rim or side, Newton on
// that feature's optimality condition, every solution certified as the closest pair): pairs that have no closed
// form or strictly convex reference - ellipsoids against capsules and polytopes, cylinders and cones against
// non-spheres. Each perturbed copy is solved on the nominal pair's features; a pair whose copies leave them (the
// step crosses onto a neighbouring feature: the derivative is not the same function on both sides) has no
// reference and is counted, not compared.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace batchcol::testing {
namespace {

struct Errors {
  double distance = 0, witness = 0, normal = 0;
};

struct Summary {
  Errors all;                              // max over the compared pairs
  std::map<std::string, std::pair<int, Errors>> by_features;  // "capsule side / ellipsoid surface" -> count, max
  int compared = 0, uncertified = 0, crossing = 0, other_status = 0;
};

void take_max(Errors& into, const Errors& e) {
  into.distance = std::max(into.distance, e.distance);
  into.witness = std::max(into.witness, e.witness);
  into.normal = std::max(into.normal, e.normal);
}

// The pairs of `batch` whose analytic status is in `statuses`, compared at the exact witness points with steps of
// h x distance (translation; rotation that over the radii sum). 1e-4: the central differences' truncation is
// O(h^2) relative to the curvature radii (>= 0.025 m here, distances >= 2% of the radii sum), ~1e-8; the
// reference's rounding (~1e-16 m over steps >= ~1e-6 m) ~1e-10.
Summary compare(const ShapeTable& shapes, const PairBatch& batch, const std::vector<DerivativeStatus>& statuses,
                double h = 1e-4) {
  const FeatureReference ref = feature_witness(shapes, batch);
  DerivativeResults d;
  differentiate_results(shapes, batch, ref.exact, DerivativeOptions{}, 0, d);
  std::vector<double> steps(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i) steps[i] = h * ref.exact.distance[i];
  const FeatureDifferences fd = feature_finite_differences(shapes, batch, ref, steps);
  Summary s;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (!ref.certified[i]) {
      ++s.uncertified;
      continue;
    }
    if (std::find(statuses.begin(), statuses.end(), d.status[i]) == statuses.end()) {
      ++s.other_status;
      continue;
    }
    if (!fd.same_features[i]) {
      ++s.crossing;
      continue;
    }
    Errors e;
    e.distance = std::max(relative_error(d.distance_gradient_a[i], fd.distance_a[i]),
                          relative_error(d.distance_gradient_b[i], fd.distance_b[i]));
    e.witness = std::max({relative_error(d.witness_a_wrt_a[i], fd.witness_a_a[i]),
                          relative_error(d.witness_a_wrt_b[i], fd.witness_a_b[i]),
                          relative_error(d.witness_b_wrt_a[i], fd.witness_b_a[i]),
                          relative_error(d.witness_b_wrt_b[i], fd.witness_b_b[i])});
    e.normal = std::max(relative_error(d.normal_wrt_a[i], fd.normal_a[i]),
                        relative_error(d.normal_wrt_b[i], fd.normal_b[i]));
    std::string fa = feature_name(shapes[batch.shape_a[i]], ref.feature_a[i]);
    std::string fb = feature_name(shapes[batch.shape_b[i]], ref.feature_b[i]);
    if (fb < fa) std::swap(fa, fb);
    auto& group = s.by_features[fa + " / " + fb];
    ++group.first;
    take_max(group.second, e);
    take_max(s.all, e);
    ++s.compared;
    if (std::getenv("BATCHCOL_PRINT_OUTLIERS") && std::max({e.distance, e.witness, e.normal}) > 1e-5)
      std::printf("outlier %s / %s (%s): d %.2e w %.2e n %.2e dist %.3e\n", fa.c_str(), fb.c_str(),
                  to_string(d.status[i]), e.distance, e.witness, e.normal, ref.exact.distance[i]);
  }
  return s;
}

void report(const char* what, const Summary& s) {
  std::printf("%s: %d pairs compared (%d uncertified, %d other status, %d crossing a feature within a step); max "
              "relative error: distance gradient %.2e, witness Jacobians %.2e, normal Jacobians %.2e\n",
              what, s.compared, s.uncertified, s.other_status, s.crossing, s.all.distance, s.all.witness,
              s.all.normal);
  for (const auto& [name, group] : s.by_features)
    std::printf("  %-40s %5d  %.2e %.2e %.2e\n", name.c_str(), group.first, group.second.distance,
                group.second.witness, group.second.normal);
}

int count_with(const Summary& s, const std::string& feature) {
  int n = 0;
  for (const auto& [name, group] : s.by_features)
    if (name.find(feature) != std::string::npos) n += group.first;
  return n;
}

// The pairs of `mixed` with one shape of `first` types and the other of `second` types.
PairBatch select(const ShapeTable& shapes, const PairBatch& mixed, const std::vector<ShapeType>& first,
                 const std::vector<ShapeType>& second) {
  const auto in = [](ShapeType t, const std::vector<ShapeType>& v) { return std::find(v.begin(), v.end(), t) != v.end(); };
  PairBatch batch;
  for (std::size_t i = 0; i < mixed.size(); ++i) {
    const ShapeType a = shapes[mixed.shape_a[i]].type, b = shapes[mixed.shape_b[i]].type;
    if ((in(a, first) && in(b, second)) || (in(b, first) && in(a, second)))
      batch.add(mixed.shape_a[i], mixed.pose_a(i), mixed.shape_b[i], mixed.pose_b(i));
  }
  return batch;
}

// `count` random separated pairs of `types` (seed), the ones with a shape of `first` types against one of `second`
// types compared (status smooth or zero_curvature) and reported.
Summary measure(const char* what, std::uint64_t seed, const std::vector<ShapeType>& types, int count,
                const std::vector<ShapeType>& first, const std::vector<ShapeType>& second) {
  Rng rng(seed);
  ShapeTable shapes;
  const PairBatch mixed = random_separated_pairs(rng, shapes, types, count);
  const Summary s = compare(shapes, select(shapes, mixed, first, second),
                            {DerivativeStatus::smooth, DerivativeStatus::zero_curvature});
  report(what, s);
  return s;
}

// The bounds on every compared pair, and almost every pair compared (certified, its steps on its features,
// not flagged nonsmooth or singular).
void expect_clean(const Summary& s) {
  EXPECT_LE(s.uncertified + s.crossing + s.other_status, s.compared / 100);
  EXPECT_LE(s.all.distance, 1e-6);
  EXPECT_LE(s.all.witness, 1e-5);
  EXPECT_LE(s.all.normal, 1e-5);
}

// Ellipsoids against capsules: the capsule's side (its segment swept: a flat of the support map along the axis)
// and its ends (spheres).
TEST(DerivativesExactFeatures, EllipsoidsAgainstCapsules) {
  const Summary s = measure("ellipsoids against capsules", 25, {ShapeType::ellipsoid, ShapeType::capsule}, 6000,
                            {ShapeType::ellipsoid}, {ShapeType::capsule});
  EXPECT_GE(s.compared, 2500);
  EXPECT_GE(count_with(s, "capsule side"), 500);
  expect_clean(s);
}

// Ellipsoids and spheres against hulls and boxes: a witness inside a face (two flats), on an edge (one) or at a
// vertex (zero_curvature: exact, the witness moves rigidly).
TEST(DerivativesExactFeatures, EllipsoidsAndSpheresAgainstPolytopes) {
  const Summary s = measure("ellipsoids/spheres against hulls/boxes", 26,
                            {ShapeType::ellipsoid, ShapeType::sphere, ShapeType::convex, ShapeType::box}, 6000,
                            {ShapeType::ellipsoid, ShapeType::sphere}, {ShapeType::convex, ShapeType::box});
  EXPECT_GE(s.compared, 2500);
  EXPECT_GE(count_with(s, "convex face"), 100);
  EXPECT_GE(count_with(s, "box face"), 100);
  expect_clean(s);
}

// Cylinders against non-spheres: rim, side and cap against curved, segment and polytope features (seed 23 and,
// below, 24: the pairs of the former test against GJK at the precision floor).
TEST(DerivativesExactFeatures, CylindersAgainstNonSpheres) {
  const std::vector<ShapeType> types = {ShapeType::cylinder, ShapeType::ellipsoid, ShapeType::capsule, ShapeType::box,
                                        ShapeType::convex};
  const Summary s = measure("cylinders against non-spheres", 23, types, 4000, {ShapeType::cylinder}, types);
  EXPECT_GE(s.compared, 1200);
  EXPECT_GE(count_with(s, "cylinder side"), 250);
  expect_clean(s);
}

// Cones against spheres, ellipsoids, boxes and cones: base, rim, apex and side.
TEST(DerivativesExactFeatures, Cones) {
  const std::vector<ShapeType> types = {ShapeType::cone, ShapeType::sphere, ShapeType::ellipsoid, ShapeType::box};
  const Summary s = measure("cones", 24, types, 4000, {ShapeType::cone}, types);
  EXPECT_GE(s.compared, 1000);
  // The side (570 pairs measured) is smooth and exact: the curvature across a generator is the circle's through
  // the witness (with the rim's, its witness Jacobians were off by up to 0.58).
  EXPECT_GE(count_with(s, "cone side"), 400);
  expect_clean(s);
}

}  // namespace
}  // namespace batchcol::testing
