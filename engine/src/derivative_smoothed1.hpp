// smoothed1's support-Jacobian estimate (smoothed_support_estimate(), derivative_smoothed1_estimate.cpp) and its last
// per-pair steps, the PSD projection of each shape's estimate and its rotation to the world frame (H = R P R^T), for a
// store block's smooth pairs together in SIMD lanes instead of pair by pair (derivative_smoothed1.cpp): the
// eigenvalues' Jacobi sweeps are a chain of divisions and square roots, ~1100 instructions per pair in scalar /
// two-lane code with the projection and the two 3x3 products (callgrind AVX2, convex8 M = 4).
#pragma once

#include "batchcol/shapes.hpp"
#include "batchcol/types.hpp"
#include "derivative_ift.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>

namespace batchcol::detail {

/// The pending smoothed1 pairs of a block, by their SmoothLanes lane: each side's estimate S (symmetric, entries
/// 00, 11, 22, 01, 02, 12) and local-to-world rotation R (row-major). finish() writes
///   H = R psd_projection(S) R^T
/// into the lane's SmoothLanes H0 with the bits of psd_projection() of each side followed by the assignment
/// H = R * S * R.transpose() of Eigen matrices (the per-pair path's, which the pairs off this path still take): every
/// lane does those functions' IEEE operations in their order (the eigenvalue sweeps until its own convergence test
/// fails, the projectors' and the products' sums in Eigen's order), so the bits do not depend on the set or on the
/// other lanes (DerivativesSmoothed1Lanes.GiveThePerPairBits).
struct Smoothed1Lanes {
  static constexpr std::size_t kLanes = SmoothLanes::kLanes;
  alignas(64) double S[2][6][kLanes];
  alignas(64) double R[2][9][kLanes];
  unsigned pending = 0;  // bit l: lane l is to be finished
  void clear() { pending = 0; }
  /// Lane l takes a pair's two estimates and rotations.
  void set(std::size_t l, const Eigen::Matrix3d& S_a, const Eigen::Matrix3d& S_b, const Eigen::Matrix3d& R_a,
           const Eigen::Matrix3d& R_b);
  /// Writes H_a, H_b of every pending lane to `lanes`.a.H0 / .b.H0 (AVX2 registers on AVX2 and AVX-512, SSE2 on the
  /// baseline set: the same bits).
  void finish(SmoothLanes& lanes, InstructionSet isa) const;
};

/// The smoothed support-map Jacobian at unit local direction u before its projection (psd_projection()):
/// 1/(M e) sum_j (S(u + e z_j) - S(u)) z_j^T with z_j standard normal in R^3 and antithetic pairs z_{2k+1} = -z_{2k}
/// (the baseline S(u) cancels within a pair: each pair adds (S(u + e z) - S(u - e z)) z^T, and only an odd M's last
/// sample takes S(u)), symmetrised. The Hessian of the smoothed convex support function is
/// symmetric PSD; the caller's projection onto that cone removes sampling noise that could make the
/// implicit-function matrix singular, a bias that vanishes as M grows. z[c][k] (c < 3, k < (M + 1) / 2; z[3] is not
/// read): the noise of antithetic pair k (the caller draws it: kernels::simd::draw_support_noise() for both sides
/// of 8 pairs at a time, counter_rng.hpp's support_noise_pair()). The shape: shape `shape` of `shapes`; the
/// M = 4 AVX2 path reads the table's type, inflation, radii and hull arrays, the others its plain record
/// (ShapeTableAccess::view()), not a ShapeView built per side for every call. `isa` (resolved): AVX2 and AVX-512
/// scan small hulls four directions per AVX2 register and take the ellipsoid sample differences, the hull
/// differences and the sample sums in AVX2 registers (at M = 4, scanned hulls and ellipsoids without inflation: all
/// in registers), with the same bits as the baseline set.
Eigen::Matrix3d smoothed_support_estimate(const ShapeTable& shapes, std::uint32_t shape, const Eigen::Vector3d& u,
                                          double e, int samples, const double* const* z, InstructionSet isa);


}  // namespace batchcol::detail
