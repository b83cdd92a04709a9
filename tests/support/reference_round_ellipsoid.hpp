// The scalar transcription of kernels/simd/wide_gjk_round_ellipsoid.inl (the reasoning is there): the Newton start
// point of a cylinder-ellipsoid or cone-ellipsoid pair, with the wide code's operations in the same order, so that
// each lane's candidate, hence its GJK answer, is bitwise the reference's. Included by reference_gjk.hpp.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"

#include <cmath>
#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// wide_gjk_round_ellipsoid.inl's disk_ellipsoid(): Newton on the contact normal against the disk of radius rd at
/// height zr (rd = 0: the point (0, 0, zr)).
template <class T>
void disk_ellipsoid(const T* E, const T* Q, const T* c, const T* ir2, T rd, T zr, T* qa, T* qb) {
  T n[3];
  {
    const T cr = std::sqrt(c[0] * c[0] + c[1] * c[1]);
    const T f = cr > T(0) ? rd / cr : T(0);
    const T v[3] = {c[0] - f * c[0], c[1] - f * c[1], c[2] - zr};
    const T p0 = ((E[0] * v[0] + E[3] * v[1]) + E[6] * v[2]) * ir2[0];
    const T p1 = ((E[1] * v[0] + E[4] * v[1]) + E[7] * v[2]) * ir2[1];
    const T p2 = ((E[2] * v[0] + E[5] * v[1]) + E[8] * v[2]) * ir2[2];
    const T m[3] = {(E[0] * p0 + E[1] * p1) + E[2] * p2, (E[3] * p0 + E[4] * p1) + E[5] * p2,
                    (E[6] * p0 + E[7] * p1) + E[8] * p2};
    const T f0 = T(1) / std::sqrt((m[0] * m[0] + m[1] * m[1]) + m[2] * m[2]);
    for (int i = 0; i < 3; ++i) n[i] = f0 * m[i];
  }
  for (int it = 0; it < kRoundEllipsoidNewtonSteps; ++it) {
    const T Qn[3] = {(Q[0] * n[0] + Q[1] * n[1]) + Q[2] * n[2], (Q[3] * n[0] + Q[4] * n[1]) + Q[5] * n[2],
                     (Q[6] * n[0] + Q[7] * n[1]) + Q[8] * n[2]};
    const T q = (n[0] * Qn[0] + n[1] * Qn[1]) + n[2] * Qn[2];
    const T is = T(1) / std::sqrt(q);
    const T rho = std::sqrt(n[0] * n[0] + n[1] * n[1]);
    const T ir = rho > T(0) ? T(1) / rho : T(0);
    const T kx = rd * ir;
    const T w[3] = {(c[0] - Qn[0] * is) - kx * n[0], (c[1] - Qn[1] * is) - kx * n[1], (c[2] - Qn[2] * is) - zr};
    const T g = (w[0] * n[0] + w[1] * n[1]) + w[2] * n[2];
    const T b[3] = {w[0] - g * n[0], w[1] - g * n[1], w[2] - g * n[2]};
    const T gp = g > T(0) ? g : T(0);
    const T iq = T(1) / q;
    const T ka = (kx * ir) * ir;
    const T m00 = (((Q[0] - (Qn[0] * Qn[0]) * iq) * is + ka * (n[1] * n[1])) + gp) + n[0] * n[0];
    const T m11 = (((Q[4] - (Qn[1] * Qn[1]) * iq) * is + ka * (n[0] * n[0])) + gp) + n[1] * n[1];
    const T m22 = ((Q[8] - (Qn[2] * Qn[2]) * iq) * is + gp) + n[2] * n[2];
    const T m01 = ((Q[1] - (Qn[0] * Qn[1]) * iq) * is - ka * (n[0] * n[1])) + n[0] * n[1];
    const T m02 = (Q[2] - (Qn[0] * Qn[2]) * iq) * is + n[0] * n[2];
    const T m12 = (Q[5] - (Qn[1] * Qn[2]) * iq) * is + n[1] * n[2];
    const T A00 = m11 * m22 - m12 * m12, A01 = m02 * m12 - m01 * m22, A02 = m01 * m12 - m02 * m11;
    const T A11 = m00 * m22 - m02 * m02, A12 = m01 * m02 - m00 * m12, A22 = m00 * m11 - m01 * m01;
    const T id = T(1) / ((m00 * A00 + m01 * A01) + m02 * A02);
    const T n1[3] = {n[0] + ((A00 * b[0] + A01 * b[1]) + A02 * b[2]) * id,
                     n[1] + ((A01 * b[0] + A11 * b[1]) + A12 * b[2]) * id,
                     n[2] + ((A02 * b[0] + A12 * b[1]) + A22 * b[2]) * id};
    const T f = T(1) / std::sqrt((n1[0] * n1[0] + n1[1] * n1[1]) + n1[2] * n1[2]);
    for (int i = 0; i < 3; ++i) n[i] = f * n1[i];
  }
  const T Qn[3] = {(Q[0] * n[0] + Q[1] * n[1]) + Q[2] * n[2], (Q[3] * n[0] + Q[4] * n[1]) + Q[5] * n[2],
                   (Q[6] * n[0] + Q[7] * n[1]) + Q[8] * n[2]};
  const T is = T(1) / std::sqrt((n[0] * Qn[0] + n[1] * Qn[1]) + n[2] * Qn[2]);
  const T rho = std::sqrt(n[0] * n[0] + n[1] * n[1]);
  const T kx = rho > T(0) ? rd / rho : T(0);
  qa[0] = kx * n[0];
  qa[1] = kx * n[1];
  qa[2] = zr;
  for (int i = 0; i < 3; ++i) qb[i] = c[i] - Qn[i] * is;
}

/// wide_gjk_round_ellipsoid.inl's side_ellipsoid(): Newton on the angle of a cylinder's side normals or a cone's
/// slant normals.
template <class T> void side_ellipsoid(const T* Q, const T* c, T r, T hy, bool cone, T* qa, T* qb) {
  const T k = cone ? T(2) * hy : T(1), z0 = cone ? r : T(0);
  T C, S;
  {
    const T u0 = Q[4] * c[0] - Q[1] * c[1], u1 = Q[0] * c[1] - Q[1] * c[0];
    const T inv = T(1) / std::sqrt(u0 * u0 + u1 * u1);
    C = u0 * inv;
    S = u1 * inv;
  }
  for (int it = 0; it < kRoundEllipsoidSideSteps; ++it) {
    const T kc = k * C, ks = k * S;
    const T Qm[3] = {(Q[0] * kc + Q[1] * ks) + Q[2] * z0, (Q[3] * kc + Q[4] * ks) + Q[5] * z0,
                     (Q[6] * kc + Q[7] * ks) + Q[8] * z0};
    const T Qm1[3] = {Q[1] * kc - Q[0] * ks, Q[4] * kc - Q[3] * ks, Q[7] * kc - Q[6] * ks};
    const T is = T(1) / std::sqrt((kc * Qm[0] + ks * Qm[1]) + z0 * Qm[2]);
    const T a1 = (Qm[0] * -ks + Qm[1] * kc) + Qm[2] * T(0);
    const T cm1 = c[1] * kc - c[0] * ks, cm2 = -(c[0] * kc + c[1] * ks);
    const T qm2 = -(Qm[0] * kc + Qm[1] * ks);
    const T g1 = cm1 - a1 * is;
    const T g2 = (cm2 - (((Qm1[0] * -ks + Qm1[1] * kc) + Qm1[2] * T(0)) + qm2) * is) + ((a1 * a1) * is) * (is * is);
    const T dt = g2 < T(0) ? -g1 / g2 : T(0);
    const T C1 = C - dt * S, S1 = S + dt * C;
    const T inv = T(1) / std::sqrt(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  const T kc = k * C, ks = k * S;
  const T Qm[3] = {(Q[0] * kc + Q[1] * ks) + Q[2] * z0, (Q[3] * kc + Q[4] * ks) + Q[5] * z0,
                   (Q[6] * kc + Q[7] * ks) + Q[8] * z0};
  const T is = T(1) / std::sqrt((kc * Qm[0] + ks * Qm[1]) + z0 * Qm[2]);
  for (int i = 0; i < 3; ++i) qb[i] = c[i] - Qm[i] * is;
  if (cone) {
    const T gd[3] = {r * C, r * S, -k};
    const T tau = ((gd[0] * qb[0] + gd[1] * qb[1]) + gd[2] * (qb[2] - hy)) / ((gd[0] * gd[0] + gd[1] * gd[1]) + gd[2] * gd[2]);
    const T tc = tau > T(1) ? T(1) : (tau < T(0) ? T(0) : tau);
    qa[0] = tc * gd[0];
    qa[1] = tc * gd[1];
    qa[2] = hy + tc * gd[2];
  } else {
    qa[0] = r * C;
    qa[1] = r * S;
    qa[2] = qb[2] > hy ? hy : (qb[2] < -hy ? -hy : qb[2]);
  }
}

/// wide_gjk_round_ellipsoid.inl's round_ellipsoid_point(): the cylinder or cone (radius r, half-height hy, its own
/// frame) against the ellipsoid (E row-major, centre c, radii rad); NaN where the closest candidate's direction does
/// not separate the shapes.
template <class T>
void round_ellipsoid_point(const T* E, const T* c, const T* rad, T r, T hy, bool cone, T* pa, T* pb) {
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T rr[3] = {rad[0] * rad[0], rad[1] * rad[1], rad[2] * rad[2]};
  const T ir2[3] = {T(1) / rr[0], T(1) / rr[1], T(1) / rr[2]};
  T P[9];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) P[3 * i + k] = E[3 * i + k] * rr[k];
  const auto q = [&](int i, int j) { return (P[3 * i] * E[3 * j] + P[3 * i + 1] * E[3 * j + 1]) + P[3 * i + 2] * E[3 * j + 2]; };
  const T Q[9] = {q(0, 0), q(0, 1), q(0, 2), q(0, 1), q(1, 1), q(1, 2), q(0, 2), q(1, 2), q(2, 2)};
  for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
  T best = std::numeric_limits<T>::infinity();
  const auto keep = [&](const T* qa, const T* qb) {
    const T d[3] = {qa[0] - qb[0], qa[1] - qb[1], qa[2] - qb[2]};
    const T n2 = (d[0] * d[0] + d[1] * d[1]) + d[2] * d[2];
    if (n2 < best) {
      for (int i = 0; i < 3; ++i) pa[i] = qa[i], pb[i] = qb[i];
      best = n2;
    }
  };
  const T zr = cone ? -hy : (c[2] < T(0) ? -hy : hy);
  {
    const T sz = cone ? T(-1) : (c[2] < T(0) ? T(-1) : T(1));
    const T f = sz / std::sqrt(Q[8]);
    const T qb[3] = {c[0] - f * Q[2], c[1] - f * Q[5], c[2] - f * Q[8]};
    const T rho = std::sqrt(qb[0] * qb[0] + qb[1] * qb[1]);
    const T k = rho > r ? r / rho : T(1);
    const T qa[3] = {k * qb[0], k * qb[1], zr};
    keep(qa, qb);
  }
  {
    T qa[3], qb[3];
    disk_ellipsoid(E, Q, c, ir2, r, zr, qa, qb);
    keep(qa, qb);
    if (cone) {
      disk_ellipsoid(E, Q, c, ir2, T(0), hy, qa, qb);
      keep(qa, qb);
    }
    side_ellipsoid(Q, c, r, hy, cone, qa, qb);
    keep(qa, qb);
  }
  const T n[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const T Qn[3] = {(Q[0] * n[0] + Q[1] * n[1]) + Q[2] * n[2], (Q[3] * n[0] + Q[4] * n[1]) + Q[5] * n[2],
                   (Q[6] * n[0] + Q[7] * n[1]) + Q[8] * n[2]};
  const T hz = hy * n[2];
  const T rs = r * std::sqrt(n[0] * n[0] + n[1] * n[1]);
  const T ext = cone ? (hz > rs - hz ? hz : rs - hz) : (hz < T(0) ? -hz : hz) + rs;
  const T lhs = ((c[0] * n[0] + c[1] * n[1]) + c[2] * n[2]) - ext;
  if (!(lhs > T(0) && lhs * lhs > (n[0] * Qn[0] + n[1] * Qn[1]) + n[2] * Qn[2]))
    for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
}

/// wide_gjk_round_ellipsoid.inl's round_ellipsoid_candidate() for one pair of a round_ellipsoid_pair() type (A's
/// frame); false where no candidate is finite.
template <class T> bool round_ellipsoid_candidate(const MinkowskiDifference<T>& D, SupportPoint<T>& sp) {
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  const bool cone = D.A->type == ShapeType::cone || D.B->type == ShapeType::cone;
  T pa[3], pb[3];
  if (D.A->type != ShapeType::ellipsoid) {
    const T E[9] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
    const T c[3] = {t.x(), t.y(), t.z()};
    const T rad[3] = {D.B->size.x(), D.B->size.y(), D.B->size.z()};
    round_ellipsoid_point(E, c, rad, D.A->size.x(), D.A->size.y(), cone, pa, pb);
  } else {
    const T E[9] = {R(0, 0), R(1, 0), R(2, 0), R(0, 1), R(1, 1), R(2, 1), R(0, 2), R(1, 2), R(2, 2)};
    const T c[3] = {-((R(0, 0) * t.x() + R(1, 0) * t.y()) + R(2, 0) * t.z()),
                    -((R(0, 1) * t.x() + R(1, 1) * t.y()) + R(2, 1) * t.z()),
                    -((R(0, 2) * t.x() + R(1, 2) * t.y()) + R(2, 2) * t.z())};
    const T rad[3] = {D.A->size.x(), D.A->size.y(), D.A->size.z()};
    T qround[3], qell[3];
    round_ellipsoid_point(E, c, rad, D.B->size.x(), D.B->size.y(), cone, qround, qell);
    const auto back = [&](const T* q, T* o) {
      for (int i = 0; i < 3; ++i) o[i] = ((R(i, 0) * q[0] + R(i, 1) * q[1]) + R(i, 2) * q[2]) + t[i];
    };
    back(qell, pa);
    back(qround, pb);
  }
  sp.a = Vec3<T>(pa[0], pa[1], pa[2]);
  sp.b = Vec3<T>(pb[0], pb[1], pb[2]);
  sp.w = Vec3<T>(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]);
  return sp.w.x() == sp.w.x() && sp.w.y() == sp.w.y() && sp.w.z() == sp.w.z();
}

}  // namespace batchcol::test_reference
