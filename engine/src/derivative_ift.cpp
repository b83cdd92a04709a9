#include "derivative_ift.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace batchcol::detail {
namespace {

void set_nan(PairJacobians& J) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Mat36* m : {&J.witness_a_a, &J.witness_a_b, &J.witness_b_a, &J.witness_b_b, &J.normal_a, &J.normal_b})
    m->setConstant(nan);
}

// Separated pairs without flats (the smooth common case, every ellipsoid pair): sd I + H_a + H_b >= sd I is
// symmetric positive definite, so K is its explicit 3x3 inverse (cofactors over the determinant, which is
// >= sd^3 > 0) and everything stays in fixed-size matrices; the general path below sizes its saddle-point system
// at run time, which cost more than the rest of the pair together. Same formulas as that path with k = 0.
void smooth_jacobians(const PairGeometry& g, const Eigen::Matrix3d& M0, PairJacobians& J) {
  const Eigen::Matrix3d K = M0.inverse();
  const Eigen::Vector3d& n = g.normal;
  const Eigen::Matrix3d n_x = skew(n);
  const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
  // F_a = [I, -[x_a]x + H_a [n]x], F_b = [-I, [x_b]x + H_b [n]x]; y = K F.
  const Eigen::Matrix3d Fa_w = g.H_a * n_x - skew(g.witness_a), Fb_w = g.H_b * n_x + skew(g.witness_b);
  const Eigen::Matrix3d HaK = g.H_a * K, HbK = g.H_b * K, TK = tangent * K;
  // Twist of a: y = [K, K Fa_w].
  J.witness_a_a << Eigen::Matrix3d::Identity() - HaK, Fa_w - HaK * Fa_w;
  J.witness_b_a << HbK, HbK * Fa_w;
  J.normal_a << -TK, -TK * Fa_w;
  // Twist of b: y = [-K, K Fb_w].
  J.witness_a_b << HaK, -HaK * Fb_w;
  J.witness_b_b << Eigen::Matrix3d::Identity() - HbK, HbK * Fb_w - Fb_w;
  J.normal_b << TK, -TK * Fb_w;
}

}  // namespace

PairJacobians implicit_jacobians(const PairGeometry& g) {
  PairJacobians J;
  distance_gradients(g, J.distance_a, J.distance_b);
  const Eigen::Vector3d& n = g.normal;
  const int ka = g.flats_a, kb = g.flats_b, k = ka + kb;
  const Eigen::Matrix3d M0 = g.distance * Eigen::Matrix3d::Identity() + g.H_a + g.H_b;
  if (k == 0 && g.distance > 1e-9 * g.scale) {
    smooth_jacobians(g, M0, J);
    return J;
  }
  if (k > 3) {  // four flat directions in 3-D are dependent
    J.dependent = true;
    set_nan(J);
    return J;
  }
  // The constraint columns are scaled to lengths (scale * flat) so that every block of the system is a length and
  // one threshold fits all of it; the multipliers come out divided by the scale and are used as C mu.
  Eigen::Vector3d C[3];
  for (int j = 0; j < ka; ++j) C[j] = g.scale * g.flat_a.col(j);
  for (int j = 0; j < kb; ++j) C[ka + j] = g.scale * g.flat_b.col(j);
  // Saddle-point system [M0 C; C^T 0] [y; mu] = [F; c], solved by eliminating the constraints in fixed sizes (a
  // dynamically sized eigendecomposition of it cost ~5x the rest of the pair): C = Q1 Rc (Gram-Schmidt), Q = [Q1,
  // Q2] orthonormal; C^T y = c fixes Q1^T y = Rc^-T c, the Q2 rows of the first block give
  // Q2^T M0 Q2 (Q2^T y) = Q2^T (F - M0 Q1 Q1^T y), and Rc mu = Q1^T (F - M0 y).
  Eigen::Matrix3d Q, Rc = Eigen::Matrix3d::Zero();
  for (int j = 0; j < k; ++j) {
    Eigen::Vector3d q = C[j];
    for (int i = 0; i < j; ++i) {
      Rc(i, j) = Q.col(i).dot(q);
      q -= Rc(i, j) * Q.col(i);
    }
    Rc(j, j) = q.norm();
    // Unit flats are independent when what is left of one after removing the others is O(1) (the diagonal of Rc
    // bounds the smallest singular value of C from above, within a factor sqrt(3) from below); below 1e-6 two
    // flats are parallel to within a micro-radian, as close to a face-face contact as the witness points'
    // accuracy can tell.
    if (!(Rc(j, j) > 1e-6 * g.scale)) {
      J.dependent = true;
      set_nan(J);
      return J;
    }
    Q.col(j) = q / Rc(j, j);
  }
  if (k == 0) Q.setIdentity();
  if (k == 1) Q.col(1) = Q.col(0).unitOrthogonal();
  if (k == 1 || k == 2) Q.col(2) = Q.col(0).cross(Q.col(1));
  // In w = Q^T y the system is T w = [Rc^-T c; Q2^T F] with T = [I_k 0; Q2^T M0 Q1, Q2^T M0 Q2]: det T is that of
  // the reduced matrix Q2^T M0 Q2, singular (touching without curvature, some penetrations) when it has an
  // eigenvalue within 1e-9 of the problem's length scale: its inverse would magnify the witness points' own error
  // (~1e-8 of that scale at the default GJK tolerance) beyond any meaning.
  const Eigen::Matrix3d QMQ = Q.transpose() * (0.5 * (M0 + M0.transpose())) * Q;
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();  // the reduced matrix, the constraint block set to the scale
  E.topLeftCorner(k, k).diagonal().setConstant(g.scale);
  E.bottomRightCorner(3 - k, 3 - k) = QMQ.bottomRightCorner(3 - k, 3 - k);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(E, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues().cwiseAbs().minCoeff() > 1e-9 * g.scale)) {
    J.singular = true;
    set_nan(J);
    return J;
  }
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T.bottomRows(3 - k) = QMQ.bottomRows(3 - k);
  const Eigen::Matrix3d T_inverse = T.inverse();
  const Mat36 rotation_of_n = (Mat36() << Eigen::Matrix3d::Zero(), skew(n)).finished();  // [0, [n]x]
  const Mat36 F_a = (Mat36() << Eigen::Matrix3d::Identity(), -skew(g.witness_a) + g.H_a * skew(n)).finished();
  const Mat36 F_b = (Mat36() << -Eigen::Matrix3d::Identity(), skew(g.witness_b) + g.H_b * skew(n)).finished();
  // Solves for one shape's twist (its constraint rows are c = C_j^T [0, [n]x], the other shape's are 0); returns
  // y, A mu_a and B mu_b.
  const auto solve = [&](const Mat36& F, bool twist_of_a, Mat36& y, Mat36& A_mu, Mat36& B_mu) {
    Mat36 rhs = Q.transpose() * F;  // rows k.. are Q2^T F; rows ..k become Rc^-T c (forward substitution)
    for (int j = 0; j < k; ++j) {
      const bool own = twist_of_a ? j < ka : j >= ka;
      Row6 c = own ? Row6(C[j].transpose() * rotation_of_n) : Row6::Zero();
      for (int i = 0; i < j; ++i) c -= Rc(i, j) * rhs.row(i);
      rhs.row(j) = c / Rc(j, j);
    }
    y = Q * (T_inverse * rhs);
    Mat36 r = Q.transpose() * (F - M0 * y);  // rows ..k: Rc mu (back substitution)
    Mat36 mu = Mat36::Zero();
    for (int j = k - 1; j >= 0; --j) {
      Row6 v = r.row(j);
      for (int i = j + 1; i < k; ++i) v -= Rc(j, i) * mu.row(i);
      mu.row(j) = v / Rc(j, j);
    }
    A_mu.setZero();
    B_mu.setZero();
    for (int j = 0; j < ka; ++j) A_mu += C[j] * mu.row(j);
    for (int j = ka; j < k; ++j) B_mu += C[j] * mu.row(j);
  };
  const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
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
