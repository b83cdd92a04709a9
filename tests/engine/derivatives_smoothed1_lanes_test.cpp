// Smoothed1Lanes (a store block's smoothed1 curvatures R psd_projection(S) R^T in SIMD lanes) gives every lane the
// bits of the per-pair path, psd_projection() and Eigen's R * S * R.transpose(), on every instruction set, whatever
// the other lanes hold: lanes converging in different numbers of Jacobi sweeps, positive definite, not finite,
// rank <= 2 (as at M = 4), diagonal; whole blocks and partial ones (pending lanes only written).
#include "derivative_smoothed1.hpp"  // engine/src
#include "derivative_support.hpp"    // engine/src
#include "support/same_results.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace batchcol::testing {
namespace {

TEST(DerivativesSmoothed1Lanes, GiveThePerPairBits) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto random = [&](int kind) {
    Eigen::Matrix3d H;
    if (kind == 0) {  // rank <= 2 before symmetrisation (M = 4's two antithetic pairs)
      const Eigen::Vector3d a(unit(rng), unit(rng), unit(rng)), b(unit(rng), unit(rng), unit(rng));
      const Eigen::Vector3d c(unit(rng), unit(rng), unit(rng)), d(unit(rng), unit(rng), unit(rng));
      H = a * c.transpose() + b * d.transpose();
    } else if (kind == 1) {  // positive definite
      Eigen::Matrix3d A;
      for (int k = 0; k < 9; ++k) A.data()[k] = unit(rng);
      H = A * A.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    } else if (kind == 2) {  // diagonal, or one off-diagonal pair
      H = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).asDiagonal();
      if (rng() % 2) H(0, 1) = H(1, 0) = unit(rng);
    } else if (kind == 3) {  // not finite
      for (int k = 0; k < 9; ++k) H.data()[k] = unit(rng);
      H(rng() % 3, rng() % 3) = rng() % 2 ? std::nan("") : INFINITY;
    } else if (kind == 4) {  // spread eigenvalues (more sweeps)
      for (int k = 0; k < 9; ++k) H.data()[k] = unit(rng);
      H.row(rng() % 3) *= 1e8;
    } else {  // negative definite or zero
      H = rng() % 2 ? Eigen::Matrix3d(-Eigen::Matrix3d::Identity()) : Eigen::Matrix3d::Zero();
    }
    return (0.5 * (H + H.transpose())).eval();
  };
  const auto rotation = [&] {
    return Eigen::Quaterniond(unit(rng), unit(rng), unit(rng), unit(rng)).normalized().toRotationMatrix();
  };
  std::vector<InstructionSet> sets = {InstructionSet::scalar};
  for (const auto isa : vector_isas_here()) sets.push_back(isa);
  constexpr std::size_t kLanes = detail::Smoothed1Lanes::kLanes;
  const double sentinel = -12345.0;
  int projected = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    detail::Smoothed1Lanes in{};
    Eigen::Matrix3d S[2][kLanes], R[2][kLanes];
    const unsigned pending = trial % 3 == 0 ? static_cast<unsigned>(rng() % 256) : 0xFFu;
    for (std::size_t l = 0; l < kLanes; ++l) {
      for (int s = 0; s < 2; ++s) S[s][l] = random(int(rng() % 6)), R[s][l] = rotation();
      in.set(l, S[0][l], S[1][l], R[0][l], R[1][l]);
    }
    in.pending = pending;
    for (const InstructionSet isa : sets) {
      detail::SmoothLanes out{};
      for (int e = 0; e < 9; ++e)
        for (std::size_t l = 0; l < kLanes; ++l) out.a.H0[e][l] = out.b.H0[e][l] = sentinel;
      in.finish(out, isa);
      for (std::size_t l = 0; l < kLanes; ++l)
        for (int s = 0; s < 2; ++s) {
          const Eigen::Matrix3d P = detail::psd_projection(S[s][l]);
          // As derivatives.cpp writes it: an assignment to an existing matrix (Eigen then sums T R^T in another
          // order than when it constructs a matrix from the expression).
          detail::PairGeometry g;
          g.H_a = R[s][l] * P * R[s][l].transpose();
          const Eigen::Matrix3d& expected = g.H_a;
          const auto& H0 = s == 0 ? out.a.H0 : out.b.H0;
          for (int e = 0; e < 9; ++e) {
            const double want = (pending >> l & 1) ? expected(e / 3, e % 3) : sentinel;
            // NaN: any NaN (its payload follows which operand the compiler put first)
            const bool same = std::isnan(want) ? std::isnan(H0[e][l]) : std::memcmp(&H0[e][l], &want, sizeof want) == 0;
            ASSERT_TRUE(same)
                << "set " << int(isa) << " lane " << l << " side " << s << " entry " << e << ": " << H0[e][l]
                << " vs " << want << "\nS =\n"
                << S[s][l];
          }
          projected += isa == InstructionSet::scalar && (pending >> l & 1) && P != S[s][l];
        }
    }
  }
  EXPECT_GT(projected, 20000);  // most lanes took the eigenvalue path
}

}  // namespace
}  // namespace batchcol::testing
