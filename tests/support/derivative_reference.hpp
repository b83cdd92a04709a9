// Reference derivatives for the derivative tests: central finite differences of the witness query, evaluated at
// witness points solved to machine precision (Newton on the optimality condition for strictly convex pairs, closed
// forms or GJK's finite termination for the others), plus random pair generators.
#pragma once

#include "batchcol/batchcol.hpp"
#include "support/generators.hpp"

#include <Eigen/Core>

#include <algorithm>
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
