// smoothed1's projection of the symmetrised support Jacobian estimate on the PSD cone (psd_projection(), from
// eigenvalues alone) against Eigen's eigendecomposition V max(L, 0) V^T, which it replaced.
#include "derivative_support.hpp"  // engine/src

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

namespace batchcol::testing {
namespace {

Eigen::Matrix3d reference(const Eigen::Matrix3d& H) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H);
  const Eigen::Vector3d clamped = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
}

// Symmetric matrices with chosen eigenvalues (signs, repeats, zeros, spreads of 1e-12 .. 1e12) in random frames.
TEST(DerivativesPsdProjection, MatchesTheEigendecomposition) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double pick[] = {0.0, 1.0, -1.0, 2.0, -3.0, 1e-12, -1e-12, 1e6, -1e6, 0.5, -0.5};
  double worst = 0.0;
  int cases = 0, negative = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Eigen::Vector3d l;
    for (int k = 0; k < 3; ++k)
      l[k] = trial % 3 == 0 ? pick[rng() % (sizeof pick / sizeof pick[0])] : unit(rng) * std::pow(10.0, 3 * unit(rng));
    const Eigen::Quaterniond q(Eigen::Vector4d(unit(rng), unit(rng), unit(rng), unit(rng)).normalized());
    const Eigen::Matrix3d R = q.toRotationMatrix();
    Eigen::Matrix3d H = R * l.asDiagonal() * R.transpose();
    H = (0.5 * (H + H.transpose())).eval();
    if (trial % 7 == 0) {  // plain random symmetric entries too
      for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) H(r, c) = H(c, r) = unit(rng);
    }
    const Eigen::Matrix3d P = detail::psd_projection(H), E = reference(H);
    const double scale = H.norm();
    ASSERT_TRUE(P.allFinite());
    EXPECT_EQ(P, P.transpose());
    const double error = scale > 0.0 ? (P - E).norm() / scale : (P - E).norm();
    worst = std::max(worst, error);
    EXPECT_LE(error, 1e-13) << "H =\n" << H;
    // PSD: no eigenvalue below rounding.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> check(P);
    EXPECT_GE(check.eigenvalues().minCoeff(), -1e-13 * scale);
    ++cases;
    negative += reference(H).isApprox(H, 1e-12) ? 0 : 1;
  }
  std::printf("psd_projection vs eigendecomposition: %d matrices (%d with a negative eigenvalue), max |P - E| / |H| "
              "%.2e\n", cases, negative, worst);
  EXPECT_GT(negative, cases / 4);
}

// The projection as it was written with Eigen expressions (main until 2026-11-26): Jacobi eigenvalues, then the
// spectral projectors as Eigen 3x3 products. psd_projection() now spells the projectors as plain loops in Eigen's
// operation order; this checks that order bit for bit (a wrong summation order differs in ~35% of the matrices).
Eigen::Matrix3d eigen_expressions(const Eigen::Matrix3d& H) {
  double a00 = H(0, 0), a11 = H(1, 1), a22 = H(2, 2), a01 = H(0, 1), a02 = H(0, 2), a12 = H(1, 2);
  const auto rotate = [](double& app, double& aqq, double& apq, double& arp, double& arq) {
    if (apq == 0.0) return;
    const double theta = (aqq - app) / (2.0 * apq), at = std::abs(theta);
    const double t = std::copysign(at > 1e150 ? 0.5 / at : 1.0 / (at + std::sqrt(at * at + 1.0)), theta);
    const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
    app -= t * apq;
    aqq += t * apq;
    apq = 0.0;
    const double rp = arp, rq = arq;
    arp = c * rp - s * rq;
    arq = s * rp + c * rq;
  };
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = std::max(std::max(std::abs(a01), std::abs(a02)), std::abs(a12));
    const double diagonal = std::max(std::max(std::abs(a00), std::abs(a11)), std::abs(a22));
    if (!(off > 1e-18 * diagonal)) break;
    rotate(a00, a11, a01, a02, a12);
    rotate(a00, a22, a02, a01, a12);
    rotate(a11, a22, a12, a01, a02);
  }
  Eigen::Vector3d l(a00, a11, a22);
  if (l[1] > l[0]) std::swap(l[0], l[1]);
  if (l[2] > l[1]) std::swap(l[1], l[2]);
  if (l[1] > l[0]) std::swap(l[0], l[1]);
  if (l[2] >= 0.0) return H;
  if (l[0] <= 0.0) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  if (l[1] >= 0.0) {
    const Eigen::Matrix3d Q = (H - l[0] * I) * (H - l[1] * I) / ((l[2] - l[0]) * (l[2] - l[1]));
    Eigen::Matrix3d P = H - l[2] * Q;
    return (0.5 * (P + P.transpose())).eval();
  }
  const Eigen::Matrix3d Q = (H - l[1] * I) * (H - l[2] * I) / ((l[0] - l[1]) * (l[0] - l[2]));
  const Eigen::Matrix3d P = l[0] * Q;
  return (0.5 * (P + P.transpose())).eval();
}

TEST(DerivativesPsdProjection, SameBitsAsTheEigenExpressions) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int projected = 0;
  for (int trial = 0; trial < 50000; ++trial) {
    Eigen::Matrix3d H;
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) H(r, c) = H(c, r) = unit(rng) * std::pow(10.0, 2 * unit(rng));
    if (trial % 4 == 0) H(rng() % 3, rng() % 3) = 0.0;  // signed zeros through x I's 0 entries
    H = (0.5 * (H + H.transpose())).eval();
    const Eigen::Matrix3d P = detail::psd_projection(H), E = eigen_expressions(H);
    ASSERT_EQ(std::memcmp(P.data(), E.data(), sizeof P), 0) << "H =\n" << H;
    projected += P != H;
  }
  EXPECT_GT(projected, 25000);  // most random symmetric matrices have a negative eigenvalue
}

TEST(DerivativesPsdProjection, KeepsNanAndSpecialCases) {
  EXPECT_EQ(detail::psd_projection(Eigen::Matrix3d::Zero()), Eigen::Matrix3d::Zero());
  EXPECT_EQ(detail::psd_projection(-Eigen::Matrix3d::Identity()), Eigen::Matrix3d::Zero());
  const Eigen::Matrix3d D = Eigen::Vector3d(2.0, 0.0, -1.0).asDiagonal();
  EXPECT_EQ(detail::psd_projection(D), Eigen::Matrix3d(Eigen::Vector3d(2.0, 0.0, 0.0).asDiagonal()));
  Eigen::Matrix3d N = Eigen::Matrix3d::Identity();
  N(0, 1) = N(1, 0) = std::nan("");
  EXPECT_TRUE(detail::psd_projection(N).hasNaN());
}

}  // namespace
}  // namespace batchcol::testing
