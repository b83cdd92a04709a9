// The scalar transcription of kernels/simd/wide_gjk_box_ellipsoid.inl (the reasoning is there): the closed-form
// start point of a box-ellipsoid pair, with the wide code's operations in the same order, so that each lane's
// candidate, hence its GJK answer, is bitwise the reference's. Included by reference_gjk.hpp.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"

#include <cmath>
#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// wide_gjk_box_ellipsoid.inl's box_ellipsoid_point(): E row-major (the ellipsoid's axes as columns), c, r the
/// ellipsoid's centre and radii, h the box's half extents, all in the box's frame; pa on the box, pb on the
/// ellipsoid (NaN where no candidate is finite). `Core`: kBoxCore, kSegmentCore (h = (0, 0, half length): the
/// edge along z and the vertex only) or kPointCore (h = 0: the vertex only).
template <class T, int Core>
void box_ellipsoid_point(const T* E, const T* c, const T* r, const T* h, T* pa, T* pb) {
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T rr[3] = {r[0] * r[0], r[1] * r[1], r[2] * r[2]};
  T P[9];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) P[3 * i + k] = E[3 * i + k] * rr[k];
  const auto q = [&](int i, int j) { return (P[3 * i] * E[3 * j] + P[3 * i + 1] * E[3 * j + 1]) + P[3 * i + 2] * E[3 * j + 2]; };
  const T Q[9] = {q(0, 0), q(0, 1), q(0, 2), q(0, 1), q(1, 1), q(1, 2), q(0, 2), q(1, 2), q(2, 2)};
  const T s[3] = {c[0] < T(0) ? T(-1) : T(1), c[1] < T(0) ? T(-1) : T(1), c[2] < T(0) ? T(-1) : T(1)};
  const auto clamp = [](T v, T e) { return v > e ? e : (v < -e ? -e : v); };
  for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
  T best = std::numeric_limits<T>::infinity();
  const auto keep = [&](const T* qa, const T* qb) {
    const T dx = qa[0] - qb[0], dy = qa[1] - qb[1], dz = qa[2] - qb[2];
    const T n2 = (dx * dx + dy * dy) + dz * dz;
    if (n2 < best) {
      for (int i = 0; i < 3; ++i) pa[i] = qa[i], pb[i] = qb[i];
      best = n2;
    }
  };
  T gap[3] = {T(0), T(0), T(0)};
  for (int k = 0; k < 3 && Core == kBoxCore; ++k) {
    const T rk = std::sqrt(Q[4 * k]);
    gap[k] = (s[k] * c[k] - rk) - h[k];
    const T f = s[k] / rk;
    const T qb[3] = {c[0] - f * Q[k], c[1] - f * Q[3 + k], c[2] - f * Q[6 + k]};
    T qa[3] = {clamp(qb[0], h[0]), clamp(qb[1], h[1]), clamp(qb[2], h[2])};
    qa[k] = s[k] * h[k];
    keep(qa, qb);
  }
  const int k = Core != kBoxCore ? 2 : (gap[0] <= gap[1] && gap[0] <= gap[2] ? 0 : (gap[1] <= gap[2] ? 1 : 2));
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  const T a = Q[4 * i], d = Q[4 * j], b = (s[i] * s[j]) * Q[3 * i + j];
  const T p0 = s[i] * c[i] - h[i], p1 = s[j] * c[j] - h[j];
  if (Core != kPointCore) {
    const T m0 = d * p0 - b * p1, m1 = a * p1 - b * p0;
    const T inv0 = T(1) / std::sqrt(m0 * m0 + m1 * m1);
    T C = m0 * inv0, S = m1 * inv0;
    for (int it = 0; it < kBoxEdgeNewtonSteps; ++it) {
      const T Qm0 = a * C + b * S, Qm1 = b * C + d * S;
      const T qq = C * Qm0 + S * Qm1;
      const T q1 = C * Qm1 - S * Qm0;
      const T qp = S * (a * S - b * C) + C * (d * C - b * S);
      const T ih = T(1) / std::sqrt(qq);
      const T h1 = q1 * ih;
      const T h2 = ((qp - qq) - h1 * h1) * ih;
      const T f1 = (C * p1 - S * p0) - h1;
      const T f2 = -(C * p0 + S * p1) - h2;
      const T dt = f2 < T(0) ? -f1 / f2 : T(0);
      const T C1 = C - dt * S, S1 = S + dt * C;
      const T inv = T(1) / std::sqrt(C1 * C1 + S1 * S1);
      C = C1 * inv;
      S = S1 * inv;
    }
    T m[3];
    m[k] = T(0);
    m[i] = s[i] * C;
    m[j] = s[j] * S;
    const T Qm[3] = {(Q[0] * m[0] + Q[1] * m[1]) + Q[2] * m[2], (Q[3] * m[0] + Q[4] * m[1]) + Q[5] * m[2],
                     (Q[6] * m[0] + Q[7] * m[1]) + Q[8] * m[2]};
    const T f = T(1) / std::sqrt((m[0] * Qm[0] + m[1] * Qm[1]) + m[2] * Qm[2]);
    const T qb[3] = {c[0] - f * Qm[0], c[1] - f * Qm[1], c[2] - f * Qm[2]};
    T qa[3];
    qa[k] = clamp(qb[k], h[k]);
    qa[i] = s[i] * h[i];
    qa[j] = s[j] * h[j];
    keep(qa, qb);
  }
  {
    const T qa[3] = {s[0] * h[0], s[1] * h[1], s[2] * h[2]};
    const T v[3] = {qa[0] - c[0], qa[1] - c[1], qa[2] - c[2]};
    T p[3], w[3];
    for (int n = 0; n < 3; ++n) {
      p[n] = (E[n] * v[0] + E[3 + n] * v[1]) + E[6 + n] * v[2];
      w[n] = rr[n] * (p[n] * p[n]);
    }
    T t = T(0);
    for (int it = 0; it < vertex_newton_steps(Core); ++it) {
      const T e0 = T(1) / (rr[0] + t), e1 = T(1) / (rr[1] + t), e2 = T(1) / (rr[2] + t);
      const T a0 = (w[0] * e0) * e0, a1 = (w[1] * e1) * e1, a2 = (w[2] * e2) * e2;
      const T S = (a0 + a1) + a2;
      const T D1 = (a0 * e0 + a1 * e1) + a2 * e2;
      t = t + (S * (std::sqrt(S) - T(1))) / D1;
    }
    const T e0 = T(1) / (rr[0] + t), e1 = T(1) / (rr[1] + t), e2 = T(1) / (rr[2] + t);
    const T S = ((w[0] * e0) * e0 + (w[1] * e1) * e1) + (w[2] * e2) * e2;
    const T f = T(1) / std::sqrt(S);
    const T y[3] = {((rr[0] * p[0]) * e0) * f, ((rr[1] * p[1]) * e1) * f, ((rr[2] * p[2]) * e2) * f};
    const T qb[3] = {((E[0] * y[0] + E[1] * y[1]) + E[2] * y[2]) + c[0], ((E[3] * y[0] + E[4] * y[1]) + E[5] * y[2]) + c[1],
                     ((E[6] * y[0] + E[7] * y[1]) + E[8] * y[2]) + c[2]};
    keep(qa, qb);
  }
  const T n[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const T Qn[3] = {(Q[0] * n[0] + Q[1] * n[1]) + Q[2] * n[2], (Q[3] * n[0] + Q[4] * n[1]) + Q[5] * n[2],
                   (Q[6] * n[0] + Q[7] * n[1]) + Q[8] * n[2]};
  const T an[3] = {n[0] < T(0) ? -n[0] : n[0], n[1] < T(0) ? -n[1] : n[1], n[2] < T(0) ? -n[2] : n[2]};
  const T lhs = ((c[0] * n[0] + c[1] * n[1]) + c[2] * n[2]) - ((h[0] * an[0] + h[1] * an[1]) + h[2] * an[2]);
  if (!(lhs > T(0) && lhs * lhs > (n[0] * Qn[0] + n[1] * Qn[1]) + n[2] * Qn[2]))
    for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
}

/// wide_gjk_box_ellipsoid.inl's box_ellipsoid_candidate() for one pair of a box_ellipsoid_pair() type (A's frame);
/// false where no candidate is finite.
template <class T> bool box_ellipsoid_candidate(const MinkowskiDifference<T>& D, SupportPoint<T>& sp) {
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  const bool a_flat = D.A->type != ShapeType::ellipsoid;
  const ShapeCore<T>& F = a_flat ? *D.A : *D.B;
  const ShapeCore<T>& L = a_flat ? *D.B : *D.A;
  const T h[3] = {F.type == ShapeType::box ? F.size.x() : T(0), F.type == ShapeType::box ? F.size.y() : T(0),
                  F.type == ShapeType::box ? F.size.z() : (F.type == ShapeType::capsule ? F.size.y() : T(0))};
  const T r[3] = {L.size.x(), L.size.y(), L.size.z()};
  const auto point = [&](const T* E, const T* c, T* qf, T* qe) {
    if (F.type == ShapeType::box) box_ellipsoid_point<T, kBoxCore>(E, c, r, h, qf, qe);
    else if (F.type == ShapeType::capsule) box_ellipsoid_point<T, kSegmentCore>(E, c, r, h, qf, qe);
    else box_ellipsoid_point<T, kPointCore>(E, c, r, h, qf, qe);
  };
  T pa[3], pb[3];
  if (a_flat) {
    const T E[9] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
    const T c[3] = {t.x(), t.y(), t.z()};
    point(E, c, pa, pb);
  } else {
    const T E[9] = {R(0, 0), R(1, 0), R(2, 0), R(0, 1), R(1, 1), R(2, 1), R(0, 2), R(1, 2), R(2, 2)};
    const T c[3] = {-((R(0, 0) * t.x() + R(1, 0) * t.y()) + R(2, 0) * t.z()),
                    -((R(0, 1) * t.x() + R(1, 1) * t.y()) + R(2, 1) * t.z()),
                    -((R(0, 2) * t.x() + R(1, 2) * t.y()) + R(2, 2) * t.z())};
    T qflat[3], qell[3];
    point(E, c, qflat, qell);
    const auto back = [&](const T* q, T* o) {
      for (int i = 0; i < 3; ++i) o[i] = ((R(i, 0) * q[0] + R(i, 1) * q[1]) + R(i, 2) * q[2]) + t[i];
    };
    back(qell, pa);
    back(qflat, pb);
  }
  sp.a = Vec3<T>(pa[0], pa[1], pa[2]);
  sp.b = Vec3<T>(pb[0], pb[1], pb[2]);
  sp.w = Vec3<T>(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]);
  return sp.w.x() == sp.w.x() && sp.w.y() == sp.w.y() && sp.w.z() == sp.w.z();
}

}  // namespace batchcol::test_reference
