// The Jacobian of a shape's support map (the Hessian of its support function sigma(u) = max_{x in A} <x, u>) in the
// shape's local frame, exact where it exists, and its randomized-smoothing estimate (Montaut et al. 2023, sec. IV;
// the slide "Randomized smoothing - 1st order"). Used by the implicit-function derivatives (derivative_ift.hpp).
#pragma once

#include "batchcol/shapes.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace batchcol::detail {

/// Directions within this of a tie of the support map count as the tie. GJK's normals for polytopes come from the
/// final simplex and are exact to a few ulps in the pairs this was written for (finite termination), and curved
/// cores give no ties; a 1e-7 band (relative: direction components, or dot-product gaps over the hull radius)
/// catches a face or edge contact with four orders of margin, while a random direction falls into it with
/// probability ~1e-7.
constexpr double kTieTolerance = 1e-7;

/// The support map's Jacobian at a unit direction u, split into a finite part H and flat directions: where u is
/// (within kTieTolerance) normal to a face or edge of the core, S jumps along that face, which the derivatives treat
/// as infinite curvature along the orthonormal columns of `flat` (the limit is taken exactly, derivative_ift.hpp).
struct SupportJacobian {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // d S(u) / d u at the unit direction u (degree -1 in |u|)
  Eigen::Matrix<double, 3, 2> flat = Eigen::Matrix<double, 3, 2>::Zero();
  int flats = 0;      // 0: no tie; 1: an edge, a capsule's or cylinder's side line, a cone's generator; 2: a face
  bool zero = false;  // S is locally constant at u (a vertex of a non-inflated core)
  bool unsupported = false;  // halfspace: no support map
  bool approximate = false;  // a cone's side: the curvature across a generator varies along it (the rim's is used)
};

/// Exact support-map Jacobian of `shape` at the unit local direction u.
SupportJacobian support_jacobian(const Shape& shape, const Eigen::Vector3d& u);

/// The full support point (core plus inflation radius) of `shape` at local direction u (not necessarily unit).
Eigen::Vector3d full_support(const Shape& shape, const Eigen::Vector3d& u);

/// The smoothed support-map Jacobian at unit local direction u: 1/(M e) sum_j (S(u + e z_j) - S(u)) z_j^T with
/// z_j standard normal in R^3 and antithetic pairs z_{2k+1} = -z_{2k} (the baseline S(u) cancels within a pair),
/// symmetrised and projected onto the positive semidefinite cone (the Hessian of the smoothed convex support
/// function is symmetric PSD; the projection removes sampling noise that could make the implicit-function matrix
/// singular, a bias that vanishes as M grows). Noise keyed by (seed, pair, sample, stream).
Eigen::Matrix3d smoothed_support_jacobian(const Shape& shape, const Eigen::Vector3d& u, double e, int samples,
                                          std::uint64_t seed, std::uint64_t pair, std::uint64_t stream);

}  // namespace batchcol::detail
