#include "derivative_ift.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace batchcol::detail {
namespace {

using System = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 7, 7>;
using Rhs = Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 7, 6>;

void set_nan(PairJacobians& J) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Mat36* m : {&J.witness_a_a, &J.witness_a_b, &J.witness_b_a, &J.witness_b_b, &J.normal_a, &J.normal_b})
    m->setConstant(nan);
}

}  // namespace

PairJacobians implicit_jacobians(const PairGeometry& g) {
  PairJacobians J;
  distance_gradients(g, J.distance_a, J.distance_b);
  const Eigen::Vector3d& n = g.normal;
  const int ka = g.flats_a, kb = g.flats_b, k = ka + kb;
  // The constraint columns are scaled to lengths (scale * flat) so that every block of the system is a length and
  // one eigenvalue threshold fits all of it; the multipliers come out divided by the scale and are used as C mu.
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 4> C(3, k);
  C.leftCols(ka) = g.scale * g.flat_a.leftCols(ka);
  C.rightCols(kb) = g.scale * g.flat_b.leftCols(kb);
  if (k > 0) {
    const Eigen::JacobiSVD<Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 4>> svd(C);
    // Unit flats are independent when their smallest singular value is O(1); below 1e-6 two flats are parallel
    // to within a micro-radian, as close to a face-face contact as the witness points' accuracy can tell.
    if (k > 3 || !(svd.singularValues()(k - 1) > 1e-6 * g.scale)) {
      J.dependent = true;
      set_nan(J);
      return J;
    }
  }
  // Separated pairs without flats (the smooth common case): sd I + H_a + H_b >= sd I is positive definite, its
  // Cholesky factor solves the system (an eigendecomposition is needed only to test the general case).
  const Eigen::Matrix3d M0 = g.distance * Eigen::Matrix3d::Identity() + g.H_a + g.H_b;
  const bool definite = k == 0 && g.distance > 1e-9 * g.scale;
  System inverse(3 + k, 3 + k);
  if (definite) {
    inverse = M0.llt().solve(Eigen::Matrix3d::Identity());
  } else {
    System S = System::Zero(3 + k, 3 + k);
    S.topLeftCorner<3, 3>() = M0;
    S.topRightCorner(3, k) = C;
    S.bottomLeftCorner(k, 3) = C.transpose();
    const Eigen::SelfAdjointEigenSolver<System> eig(0.5 * (S + S.transpose()));
    const auto lambda = eig.eigenvalues();
    if (!(lambda.cwiseAbs().minCoeff() > 1e-9 * g.scale)) {
      J.singular = true;
      set_nan(J);
      return J;
    }
    inverse = eig.eigenvectors() * lambda.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  }
  const Mat36 rotation_of_n = (Mat36() << Eigen::Matrix3d::Zero(), skew(n)).finished();  // [0, [n]x]
  const Mat36 F_a = (Mat36() << Eigen::Matrix3d::Identity(), -skew(g.witness_a) + g.H_a * skew(n)).finished();
  const Mat36 F_b = (Mat36() << -Eigen::Matrix3d::Identity(), skew(g.witness_b) + g.H_b * skew(n)).finished();
  const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
  // Solves for one shape's twist; returns y, A mu_a and B mu_b.
  const auto solve = [&](const Mat36& F, bool twist_of_a, Mat36& y, Mat36& A_mu, Mat36& B_mu) {
    Rhs rhs = Rhs::Zero(3 + k, 6);
    rhs.topRows<3>() = F;
    if (twist_of_a && ka > 0) rhs.middleRows(3, ka) = C.leftCols(ka).transpose() * rotation_of_n;
    if (!twist_of_a && kb > 0) rhs.bottomRows(kb) = C.rightCols(kb).transpose() * rotation_of_n;
    const Rhs sol = inverse * rhs;
    y = sol.topRows<3>();
    A_mu = C.leftCols(ka) * sol.middleRows(3, ka);
    B_mu = C.rightCols(kb) * sol.bottomRows(kb);
  };
  Mat36 y, A_mu, B_mu;
  solve(F_a, true, y, A_mu, B_mu);
  J.witness_a_a = F_a - g.H_a * y - A_mu;
  J.witness_b_a = g.H_b * y + B_mu;
  J.normal_a = -tangent * y;
  solve(F_b, false, y, A_mu, B_mu);
  J.witness_a_b = -(g.H_a * y + A_mu);
  J.witness_b_b = g.H_b * y + B_mu - F_b;
  J.normal_b = -tangent * y;
  return J;
}

}  // namespace batchcol::detail
