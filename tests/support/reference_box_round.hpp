// The scalar transcription of kernels/simd/wide_gjk_box_round.inl (the reasoning is there): the closed-form start
// point of a box-cylinder or box-cone pair, with the wide code's operations in the same order, so that each lane's
// candidate, hence its GJK answer, is bitwise the reference's. Included by reference_gjk.hpp.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/minkowski.hpp"

#include <cmath>
#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

/// wide_gjk_box_round.inl's edge_rim(): the rim point px (radius r, height zr) nearest to the line p + z d, its
/// foot's z (`along`); true where the foot is on the edge (|z| <= hk).
template <class T>
bool edge_rim(T r, T zr, const Vec3<T>& p, const Vec3<T>& d, T hk, Vec3<T>& px, T& along) {
  const auto dot = [](const Vec3<T>& x, const Vec3<T>& y) { return (x.x() * y.x() + x.y() * y.y()) + x.z() * y.z(); };
  const Vec3<T> w(-p.x(), -p.y(), zr - p.z());
  const T tr = T(2) * r;
  const T twx = tr * w.x(), twy = tr * w.y(), rdx = r * d.x(), rdy = r * d.y(), wd = dot(w, d);
  T best = std::numeric_limits<T>::infinity(), C = T(1), S = T(0);
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const T cj = T(kEdgeRimCos[j]), sj = T(kEdgeRimSin[j]);
    const T A = cj * twx + sj * twy, B = cj * rdx + sj * rdy;
    const T up = wd + B, dn = wd - B;
    const T fp = A - up * up, fm = (-A) - dn * dn;
    if (fp < best) best = fp, C = cj, S = sj;
    if (fm < best) best = fm, C = -cj, S = -sj;
  }
  for (int it = 0; it < kEdgeRimNewtonSteps; ++it) {
    const Vec3<T> v(r * C - p.x(), r * S - p.y(), zr - p.z());
    const Vec3<T> v1(-(r * S), r * C, T(0)), v2(-(r * C), -(r * S), T(0));
    const T vb = dot(v, d), v1b = dot(v1, d), v2b = dot(v2, d);
    const T g = dot(v, v1) - vb * v1b;
    const T h = (dot(v1, v1) + dot(v, v2)) - (v1b * v1b + vb * v2b);
    const T dt = h > T(0) ? -g / h : T(0);
    const T C1 = C - dt * S, S1 = S + dt * C;
    const T inv = T(1) / std::sqrt(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  px = Vec3<T>(r * C, r * S, zr);
  const Vec3<T> v(px.x() - p.x(), px.y() - p.y(), px.z() - p.z());
  along = dot(v, d);
  return along <= hk && along >= -hk;
}

/// wide_gjk_box_round.inl's box_round_point(): Rr row-major (Y's rotation in the box's frame), c Y's centre, r, hy
/// its radius and half-height, h the box's half extents; pa on the box, pb on Y (NaN where there is none).
template <class T>
void box_round_point(const T* Rr, const T* c, T r, T hy, bool cone, const T* h, T* pa, T* pb) {
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T b[3] = {Rr[2], Rr[5], Rr[8]};
  const T s[3] = {c[0] < T(0) ? T(-1) : T(1), c[1] < T(0) ? T(-1) : T(1), c[2] < T(0) ? T(-1) : T(1)};
  const auto clamp = [](T v, T e) { return v > e ? e : (v < -e ? -e : v); };
  const auto dot = [](const T* x, const T* y) { return (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2]; };
  for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
  T best = std::numeric_limits<T>::infinity();
  const auto keep = [&](bool ok, const T* qa, const T* qb) {
    const T d[3] = {qa[0] - qb[0], qa[1] - qb[1], qa[2] - qb[2]};
    const T n2 = dot(d, d);
    if (ok && n2 < best) {
      for (int i = 0; i < 3; ++i) pa[i] = qa[i], pb[i] = qb[i];
      best = n2;
    }
  };
  const auto back = [&](const T* q, T* o) {
    for (int i = 0; i < 3; ++i) o[i] = ((Rr[3 * i] * q[0] + Rr[3 * i + 1] * q[1]) + Rr[3 * i + 2] * q[2]) + c[i];
  };
  for (int k = 0; k < 3; ++k) {
    const T ms = -s[k];
    const T d[3] = {ms * Rr[3 * k], ms * Rr[3 * k + 1], ms * Rr[3 * k + 2]};
    const T rho = std::sqrt(d[0] * d[0] + d[1] * d[1]);
    const T kf = rho > T(0) ? r / rho : T(0);
    T sy[3];
    if (cone) {
      const bool apex = hy * d[2] >= (-hy) * d[2] + r * rho;
      sy[0] = apex ? T(0) : d[0] * kf;
      sy[1] = apex ? T(0) : d[1] * kf;
      sy[2] = apex ? hy : -hy;
    } else {
      sy[0] = d[0] * kf;
      sy[1] = d[1] * kf;
      sy[2] = d[2] < T(0) ? -hy : hy;
    }
    T qb[3], qa[3];
    back(sy, qb);
    for (int i = 0; i < 3; ++i) qa[i] = clamp(qb[i], h[i]);
    qa[k] = s[k] * h[k];
    keep(true, qa, qb);
  }
  for (int k = 0; k < 3; ++k) {
    T p0[3] = {s[0] * h[0], s[1] * h[1], s[2] * h[2]}, dir[3] = {T(0), T(0), T(0)};
    p0[k] = T(0);
    dir[k] = T(1);
    const T hk = h[k];
    const T v[3] = {p0[0] - c[0], p0[1] - c[1], p0[2] - c[2]};
    const Vec3<T> pr((Rr[0] * v[0] + Rr[3] * v[1]) + Rr[6] * v[2], (Rr[1] * v[0] + Rr[4] * v[1]) + Rr[7] * v[2],
                     (Rr[2] * v[0] + Rr[5] * v[1]) + Rr[8] * v[2]);
    const Vec3<T> dr(Rr[3 * k], Rr[3 * k + 1], Rr[3 * k + 2]);
    {
      const T zr = cone ? -hy : (pr.z() < T(0) ? -hy : hy);
      Vec3<T> px;
      T along;
      const bool ok = edge_rim(r, zr, pr, dr, hk, px, along);
      T qa[3], qb[3];
      for (int i = 0; i < 3; ++i) {
        qa[i] = p0[i] + along * dir[i];
        qb[i] = ((Rr[3 * i] * px.x() + Rr[3 * i + 1] * px.y()) + Rr[3 * i + 2] * px.z()) + c[i];
      }
      keep(ok, qa, qb);
      if (cone) {
        const T kr = T(2) * hy;
        const T a2 = dr.x() * dr.x() + dr.y() * dr.y();
        const T kap = -(r * dr.z()) / kr;
        const T disc = a2 - kap * kap;
        const T root = std::sqrt(disc > T(0) ? disc : T(0));
        const T Cp = (kap * dr.x() - root * dr.y()) / a2, Sp = (kap * dr.y() + root * dr.x()) / a2;
        const T Cm = (kap * dr.x() + root * dr.y()) / a2, Sm = (kap * dr.y() - root * dr.x()) / a2;
        const T zo = pr.z() - hy;
        const T gp = kr * (Cp * pr.x() + Sp * pr.y()) + r * zo, gm = kr * (Cm * pr.x() + Sm * pr.y()) + r * zo;
        const bool plus = gp >= gm;
        const T C = plus ? Cp : Cm, S = plus ? Sp : Sm, g = plus ? gp : gm;
        const T gd[3] = {r * C, r * S, -kr}, w0[3] = {pr.x(), pr.y(), zo}, d3[3] = {dr.x(), dr.y(), dr.z()};
        const T aa = dot(d3, d3), bq = dot(d3, gd), cq = dot(gd, gd), dd = dot(d3, w0), ee = dot(gd, w0);
        const T denom = aa * cq - bq * bq;
        const T se = (bq * ee - cq * dd) / denom, tau = (aa * ee - bq * dd) / denom;
        const bool ok2 = disc > T(0) && g > T(0) && tau >= T(0) && tau <= T(1) && se >= -hk && se <= hk;
        const T qx[3] = {tau * gd[0], tau * gd[1], hy + tau * gd[2]};
        T ya[3], xb[3];
        for (int i = 0; i < 3; ++i) {
          ya[i] = p0[i] + se * dir[i];
          xb[i] = ((Rr[3 * i] * qx[0] + Rr[3 * i + 1] * qx[1]) + Rr[3 * i + 2] * qx[2]) + c[i];
        }
        keep(ok2, ya, xb);
      }
    }
    if (!cone) {
      const T bq = dr.z(), d1 = (dr.x() * pr.x() + dr.y() * pr.y()) + dr.z() * pr.z();
      const T se = (bq * pr.z() - d1) / (T(1) - bq * bq);
      const T q[3] = {pr.x() + se * dr.x(), pr.y() + se * dr.y(), pr.z() + se * dr.z()};
      const T rho = std::sqrt(q[0] * q[0] + q[1] * q[1]);
      const T f = r / rho;
      const bool ok = se <= hk && se >= -hk && q[2] <= hy && q[2] >= -hy && rho > r;
      const T qy[3] = {f * q[0], f * q[1], q[2]};
      T qa[3], qb[3];
      for (int i = 0; i < 3; ++i) qa[i] = p0[i] + se * dir[i];
      back(qy, qb);
      keep(ok, qa, qb);
    }
  }
  {
    const T qa[3] = {s[0] * h[0], s[1] * h[1], s[2] * h[2]};
    const T w[3] = {qa[0] - c[0], qa[1] - c[1], qa[2] - c[2]};
    const T wy[3] = {(Rr[0] * w[0] + Rr[3] * w[1]) + Rr[6] * w[2], (Rr[1] * w[0] + Rr[4] * w[1]) + Rr[7] * w[2],
                     (Rr[2] * w[0] + Rr[5] * w[1]) + Rr[8] * w[2]};
    const T z = wy[2];
    const T rho = std::sqrt(wy[0] * wy[0] + wy[1] * wy[1]);
    T zq, fr;
    if (cone) {
      const T kr = T(2) * hy;
      const T sg = (rho * r - kr * (z - hy)) / (r * r + kr * kr);
      const T sgc = sg > T(1) ? T(1) : (sg < T(0) ? T(0) : sg);
      const bool below = z < -hy;
      zq = below ? -hy : hy - kr * sgc;
      fr = below ? (rho > r ? r : rho) : sgc * r;
    } else {
      zq = clamp(z, hy);
      fr = rho > r ? r : rho;
    }
    const T f = rho > T(0) ? fr / rho : T(0);
    const T y[3] = {f * wy[0], f * wy[1], zq};
    T qb[3];
    back(y, qb);
    keep(true, qa, qb);
  }
  if (cone) {
    T qb[3], qa[3];
    for (int i = 0; i < 3; ++i) qb[i] = c[i] + hy * b[i];
    for (int i = 0; i < 3; ++i) qa[i] = clamp(qb[i], h[i]);
    keep(true, qa, qb);
  }
  const T n[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const T bn = dot(b, n);
  const T t2 = dot(n, n) - bn * bn;
  const T sq = r * std::sqrt(t2 > T(0) ? t2 : T(0));
  const T hb = hy * bn;
  const T ext = cone ? (-hb > hb + sq ? -hb : hb + sq) : (hb < T(0) ? -hb : hb) + sq;
  const T an[3] = {n[0] < T(0) ? -n[0] : n[0], n[1] < T(0) ? -n[1] : n[1], n[2] < T(0) ? -n[2] : n[2]};
  if (!((dot(c, n) - ext) - ((h[0] * an[0] + h[1] * an[1]) + h[2] * an[2]) > T(0)))
    for (int i = 0; i < 3; ++i) pa[i] = pb[i] = nan;
}

/// wide_gjk_box_round.inl's box_round_candidate() for one pair of a box_round_pair() type (A's frame); false where
/// no candidate is finite.
template <class T> bool box_round_candidate(const MinkowskiDifference<T>& D, SupportPoint<T>& sp) {
  const auto& R = D.b_in_a.R;
  const Vec3<T>& t = D.b_in_a.t;
  const bool cone = D.A->type == ShapeType::cone || D.B->type == ShapeType::cone;
  T pa[3], pb[3];
  if (D.A->type == ShapeType::box) {
    const T Rr[9] = {R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
    const T c[3] = {t.x(), t.y(), t.z()};
    const T h[3] = {D.A->size.x(), D.A->size.y(), D.A->size.z()};
    box_round_point(Rr, c, D.B->size.x(), D.B->size.y(), cone, h, pa, pb);
  } else {
    const T Rr[9] = {R(0, 0), R(1, 0), R(2, 0), R(0, 1), R(1, 1), R(2, 1), R(0, 2), R(1, 2), R(2, 2)};
    const T c[3] = {-((R(0, 0) * t.x() + R(1, 0) * t.y()) + R(2, 0) * t.z()),
                    -((R(0, 1) * t.x() + R(1, 1) * t.y()) + R(2, 1) * t.z()),
                    -((R(0, 2) * t.x() + R(1, 2) * t.y()) + R(2, 2) * t.z())};
    const T h[3] = {D.B->size.x(), D.B->size.y(), D.B->size.z()};
    T qbox[3], qround[3];
    box_round_point(Rr, c, D.A->size.x(), D.A->size.y(), cone, h, qbox, qround);
    const auto back = [&](const T* q, T* o) {
      for (int i = 0; i < 3; ++i) o[i] = ((R(i, 0) * q[0] + R(i, 1) * q[1]) + R(i, 2) * q[2]) + t[i];
    };
    back(qround, pa);
    back(qbox, pb);
  }
  sp.a = Vec3<T>(pa[0], pa[1], pa[2]);
  sp.b = Vec3<T>(pb[0], pb[1], pb[2]);
  sp.w = Vec3<T>(pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]);
  return sp.w.x() == sp.w.x() && sp.w.y() == sp.w.y() && sp.w.z() == sp.w.z();
}

}  // namespace batchcol::test_reference
