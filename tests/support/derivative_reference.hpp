// Reference derivatives for the derivative tests: central finite differences of the witness query, evaluated at
// witness points solved to machine precision (Newton on the optimality condition for strictly convex pairs, closed
// forms or GJK's finite termination for the others), plus random pair generators.
#pragma once

#include "batchcol/batchcol.hpp"
#include "support/generators.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace batchcol::testing {

using Mat36 = Eigen::Matrix<double, 3, 6>;
using Row6 = Eigen::Matrix<double, 1, 6>;

/// The pose after the twist h * xi (left, world frame): R <- exp(h w) R, t <- exp(h w) t + h v.
Pose twisted(const Pose& pose, const Eigen::Matrix<double, 6, 1>& xi, double h);

/// Witness-level query options at the precision floor (the tests' tight reference).
QueryOptions tight_query();

/// Runs `batch` at tight_query() and replaces, for pairs of two strictly convex shapes (spheres, ellipsoids, any
/// inflation), the witness points by Newton's solution of z + S_a(z) - S_b(-z) = 0 (the kernels' support
/// functions; a finite-difference Jacobian, so the solution depends on the optimality condition only; the residual
/// reaches ~1e-16 of the shapes' size), and for a sphere against a non-inflated cylinder or box by the closest
/// point to the sphere's centre in closed form.
PairResults exact_witness(const ShapeTable& shapes, const PairBatch& batch);

/// Central differences of every pair of `batch` with steps h_i (twist components scaled: translation h, rotation
/// h / scale_i): all 24 perturbed copies of all pairs run as one exact_witness() batch.
struct FiniteDifferences {
  std::vector<Row6> distance_a, distance_b;
  std::vector<Mat36> witness_a_a, witness_a_b, witness_b_a, witness_b_b, normal_a, normal_b;
};
FiniteDifferences finite_differences(const ShapeTable& shapes, const PairBatch& batch, const std::vector<double>& h);

/// max |A - B| / max(max |B|, 1e-3). The floor: a Jacobian that is exactly zero (a polytope vertex's witness
/// w.r.t. the other body, a face's normal) has finite differences of up to ~5e-9 (the reference's rounding of
/// ~4e-15 m over steps down to ~1e-6 m), which this compares at 5e-6; the largest entry of every non-zero Jacobian in
/// the tests (translation columns O(1), rotation columns O(shape size >= 0.05 m), normals O(1 / length)) is far
/// above 1e-3, so the floor never dilutes them.
template <class M> double relative_error(const M& a, const M& b) {
  const double ref = b.cwiseAbs().maxCoeff();
  const double diff = (a - b).cwiseAbs().maxCoeff();
  return diff / std::max(ref, 1e-3);
}

/// `count` separated pairs between shapes drawn from `types` (each pair: two random types), centre distance
/// (bounding radii sum) x [0.8, 2]; pairs whose tight distance is below 2% of that sum are dropped.
PairBatch random_separated_pairs(Rng& rng, ShapeTable& shapes, const std::vector<ShapeType>& types, int count);

}  // namespace batchcol::testing

namespace batchcol::testing {

/// The feature of a shape a witness lies on, by kind and index (see feature_name()). `smooth`: a sphere's or an
/// ellipsoid's whole surface; the others are a face, edge or vertex of a polytope, a capsule's segment or end, a
/// cylinder's cap, rim or side, a cone's base, rim, side or apex (each swept by the shape's round radius).
struct Feature {
  enum Kind { none, smooth, point, line, plane, circle, cylinder_side, cone_side } kind = none;
  int index = 0;
  bool operator==(const Feature& o) const { return kind == o.kind && index == o.index; }
};

/// "cylinder rim", "hull face", ...: for reports.
std::string feature_name(const Shape& shape, const Feature& f);

/// Witness points solved to machine precision for separated pairs of spheres, ellipsoids, capsules, cylinders,
/// cones, boxes and hulls (any inflation), by locking each witness on its feature: the tight GJK witness names the
/// candidate features (those within 1e-7 bounding radii of it), every candidate pair is solved by Newton on its
/// smooth optimality condition (a feature's closest point is closed form: a point, a line, a plane, a circle, an
/// infinite cylinder or cone; an ellipsoid enters by its support map), and the solution kept is the one that is
/// certified: each witness in its feature's extent and a support point of its whole shape along the normal (within
/// 1e-12 of the radii sum), the smallest distance among those. Pairs without a certified solution keep GJK's
/// answer with `certified` 0.
struct FeatureReference {
  PairResults exact;
  std::vector<Feature> feature_a, feature_b;
  std::vector<std::uint8_t> certified;
};
FeatureReference feature_witness(const ShapeTable& shapes, const PairBatch& batch);

/// Central differences (steps as finite_differences()) with every perturbed copy solved on the nominal pair's
/// features: exact where the features are unchanged. `same_features[i]` is 0 when a copy's solution on those
/// features is not certified (the step crosses onto another feature): such pairs have no valid reference.
struct FeatureDifferences : FiniteDifferences {
  std::vector<std::uint8_t> same_features;
};
FeatureDifferences feature_finite_differences(const ShapeTable& shapes, const PairBatch& batch,
                                              const FeatureReference& nominal, const std::vector<double>& h);

}  // namespace batchcol::testing
