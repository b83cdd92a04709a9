// The scalar transcription of kernels/simd/wide_gjk_rim_rim.inl (the reasoning is there): the rim-rim, rim-cap,
// apex and capsule-segment start candidates of cylinder / cone / capsule pairs, with the wide code's operations in
// the same order, so that each lane's candidate, hence its GJK answer, is bitwise the reference's. Included by
// reference_gjk.hpp, whose rim_candidate() calls them.
#pragma once

#include "kernels/gjk.hpp"
#include "kernels/math.hpp"
#include "support/reference_box_round.hpp"

#include <cmath>
#include <limits>

namespace batchcol::test_reference {

using namespace batchcol::kernels;

namespace rim_ops {
// The wide kernel's V3 arithmetic, component by component (dot3: kernels/math.hpp's association order).
template <class T> Vec3<T> add(const Vec3<T>& a, const Vec3<T>& b) { return Vec3<T>(a.x() + b.x(), a.y() + b.y(), a.z() + b.z()); }
template <class T> Vec3<T> sub(const Vec3<T>& a, const Vec3<T>& b) { return Vec3<T>(a.x() - b.x(), a.y() - b.y(), a.z() - b.z()); }
template <class T> Vec3<T> scale(T s, const Vec3<T>& a) { return Vec3<T>(s * a.x(), s * a.y(), s * a.z()); }
}  // namespace rim_ops

/// wide_gjk_rim_rim.inl's solid_point(): the point of solid Y (c, b, ry, hy, cone) nearest to w.
template <class T> Vec3<T> solid_point(const Vec3<T>& w, const Vec3<T>& c, const Vec3<T>& b, T ry, T hy, bool cone) {
  using namespace rim_ops;
  const Vec3<T> v = sub(w, c);
  const T z = dot3(v, b);
  const Vec3<T> e = sub(v, scale(z, b));
  const T rho = std::sqrt(dot3(e, e));
  T zq, fr;
  if (cone) {
    const T kr = T(2) * hy;
    const T sg = (rho * ry - kr * (z - hy)) / (ry * ry + kr * kr);
    const T sgc = sg > T(1) ? T(1) : (sg < T(0) ? T(0) : sg);
    const bool below = z < -hy;
    zq = below ? -hy : hy - kr * sgc;
    fr = below ? (rho > ry ? ry : rho) : sgc * ry;
  } else {
    zq = z > hy ? hy : (z < -hy ? -hy : z);
    fr = rho > ry ? ry : rho;
  }
  const T f = rho > T(0) ? fr / rho : T(0);
  return add(add(c, scale(zq, b)), scale(f, e));
}

/// wide_gjk_rim_rim.inl's lateral_start(): rim_lateral()'s start angle (C, S), the best of a few sampled angles
/// (kEdgeRimSamples; a cylinder's in the -|D1| - B^2 form).
template <class T>
void lateral_start(T r, T zr, const Vec3<T>& c, const Vec3<T>& b, T ry, T hy, bool cone, T& C, T& S) {
  const Vec3<T> w(-c.x(), -c.y(), zr - c.z());
  const T tr = T(2) * r, kr = T(2) * hy;
  const T wb = dot3(w, b);
  const T dx = tr * (w.x() - wb * b.x()), dy = tr * (w.y() - wb * b.y()), rbx = r * b.x(), rby = r * b.y();
  if (!cone) {
    T best = -std::numeric_limits<T>::infinity(), Cb = T(1), Sb = T(0), Db = T(0);
    for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
      const T cj = T(kEdgeRimCos[j]), sj = T(kEdgeRimSin[j]);
      const T D1 = cj * dx + sj * dy, B = cj * rbx + sj * rby;
      const T g = (D1 < -D1 ? -D1 : D1) + B * B;  // wmax(D1, -D1)
      if (g > best) best = g, Cb = cj, Sb = sj, Db = D1;
    }
    const bool flip = Db > T(0);
    C = flip ? -Cb : Cb;
    S = flip ? -Sb : Sb;
    return;
  }
  const T K = (dot3(w, w) + r * r) - wb * wb;
  T best = std::numeric_limits<T>::infinity();
  C = T(1);
  S = T(0);
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const T cj = T(kEdgeRimCos[j]), sj = T(kEdgeRimSin[j]);
    const T D1 = cj * dx + sj * dy, B = cj * rbx + sj * rby;
    const T t0 = K - B * B;
    const T pp = t0 + D1, pm = t0 - D1;
    const T fp = kr * std::sqrt(pp > T(0) ? pp : T(0)) + ry * B;
    const T fm = kr * std::sqrt(pm > T(0) ? pm : T(0)) - ry * B;
    if (fp < best) best = fp, C = cj, S = sj;
    if (fm < best) best = fm, C = -cj, S = -sj;
  }
}

/// wide_gjk_rim_rim.inl's rim_rim(): X's rim (r, zr) against Y's rim (centre q, axis b, radius ry); false where
/// py is undefined.
template <class T>
bool rim_rim(T r, T zr, const Vec3<T>& q, const Vec3<T>& b, T ry, Vec3<T>& px, Vec3<T>& py) {
  using namespace rim_ops;
  const Vec3<T> w(-q.x(), -q.y(), zr - q.z());
  const T tr = T(2) * r, ty = T(2) * ry;
  const T twx = tr * w.x(), twy = tr * w.y(), rbx = r * b.x(), rby = r * b.y();
  const T wb = dot3(w, b), base = dot3(w, w) + r * r;
  T best = std::numeric_limits<T>::infinity(), C = T(1), S = T(0);
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const T cj = T(kEdgeRimCos[j]), sj = T(kEdgeRimSin[j]);
    const T A = cj * twx + sj * twy, B = cj * rbx + sj * rby;
    const T up = wb + B, dn = wb - B;
    const T pp = (base + A) - up * up, pm = (base - A) - dn * dn;
    const T fp = A - ty * std::sqrt(pp > T(0) ? pp : T(0));
    const T fm = (-A) - ty * std::sqrt(pm > T(0) ? pm : T(0));
    if (fp < best) best = fp, C = cj, S = sj;
    if (fm < best) best = fm, C = -cj, S = -sj;
  }
  for (int it = 0; it < kRimRimNewtonSteps; ++it) {
    const Vec3<T> v(r * C - q.x(), r * S - q.y(), zr - q.z());
    const Vec3<T> v1(-(r * S), r * C, T(0)), v2(-(r * C), -(r * S), T(0));
    const T vb = dot3(v, b), v1b = dot3(v1, b), v2b = dot3(v2, b);
    const T vv1 = dot3(v, v1), hh = dot3(v1, v1) + dot3(v, v2);
    const T g = vv1 - vb * v1b;
    const T h = hh - (v1b * v1b + vb * v2b);
    const T ir = T(1) / std::sqrt(dot3(v, v) - vb * vb);
    const T r1 = g * ir, r2 = (h - r1 * r1) * ir;
    const T f1 = vv1 - ry * r1, f2 = hh - ry * r2;
    const T dt = f2 > T(0) ? -f1 / f2 : T(0);
    const T C1 = C - dt * S, S1 = S + dt * C;
    const T inv = T(1) / std::sqrt(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  px = Vec3<T>(r * C, r * S, zr);
  const Vec3<T> v = sub(px, q);
  const Vec3<T> e = sub(v, scale(dot3(v, b), b));
  const T rho = std::sqrt(dot3(e, e));
  py = add(q, scale(ry / rho, e));
  return rho > T(0);
}

/// wide_gjk_rim_rim.inl's rim_disk(): X's rim (r, zr) against Y's cap disc (centre q, normal nrm, radius ry).
template <class T>
bool rim_disk(T r, T zr, const Vec3<T>& q, const Vec3<T>& nrm, T ry, Vec3<T>& px, Vec3<T>& py) {
  using namespace rim_ops;
  const T k = r / std::sqrt(nrm.x() * nrm.x() + nrm.y() * nrm.y());
  px = Vec3<T>(-(k * nrm.x()), -(k * nrm.y()), zr);
  const Vec3<T> v = sub(px, q);
  const T s = dot3(v, nrm);
  const Vec3<T> e = sub(v, scale(s, nrm));
  py = add(q, e);
  return s > T(0) && dot3(e, e) <= ry * ry;
}

/// wide_gjk_rim_rim.inl's slant_line(): a cone's slant (r, hx) against the line p + z d, |z| <= hs.
template <class T>
bool slant_line(T r, T hx, const Vec3<T>& p, const Vec3<T>& d, T hs, Vec3<T>& px, T& along) {
  const T kr = T(2) * hx;
  const T a2 = d.x() * d.x() + d.y() * d.y();
  const T kap = -(r * d.z()) / kr;
  const T disc = a2 - kap * kap;
  const T root = std::sqrt(disc > T(0) ? disc : T(0));
  const T Cp = (kap * d.x() - root * d.y()) / a2, Sp = (kap * d.y() + root * d.x()) / a2;
  const T Cm = (kap * d.x() + root * d.y()) / a2, Sm = (kap * d.y() - root * d.x()) / a2;
  const T zo = p.z() - hx;
  const T gp = kr * (Cp * p.x() + Sp * p.y()) + r * zo, gm = kr * (Cm * p.x() + Sm * p.y()) + r * zo;
  const bool plus = gp >= gm;
  const T C = plus ? Cp : Cm, S = plus ? Sp : Sm, g = plus ? gp : gm;
  const Vec3<T> gd(r * C, r * S, -kr), w0(p.x(), p.y(), zo);
  const T aa = dot3(d, d), bq = dot3(d, gd), cq = dot3(gd, gd), dd = dot3(d, w0), ee = dot3(gd, w0);
  const T denom = aa * cq - bq * bq;
  along = (bq * ee - cq * dd) / denom;
  const T tau = (aa * ee - bq * dd) / denom;
  px = Vec3<T>(tau * gd.x(), tau * gd.y(), hx + tau * gd.z());
  return disc > T(0) && g > T(0) && tau >= T(0) && tau <= T(1) && along >= -hs && along <= hs;
}

/// wide_gjk_rim_rim.inl's side_slant(): a cylinder's side (rc, axis p + z d, |z| <= hc) against a cone's slant.
template <class T>
bool side_slant(T rc, T hc, T r, T hx, const Vec3<T>& p, const Vec3<T>& d, Vec3<T>& px, Vec3<T>& py) {
  using namespace rim_ops;
  T along;
  const bool ok = slant_line(r, hx, p, d, hc, px, along);
  const Vec3<T> q = add(p, scale(along, d));
  const Vec3<T> u = sub(px, q);
  const T un = std::sqrt(dot3(u, u));
  py = add(q, scale(rc / un, u));
  return ok && un > rc;
}

/// wide_gjk_rim_rim.inl's slant_slant(): cone X (r, hx, own frame) against cone Y (c, b, ry, hy) slant to slant;
/// false where the generators' closest points are not both interior or Y is not beyond X along the normal.
template <class T>
bool slant_slant(T r, T hx, const Vec3<T>& c, const Vec3<T>& b, T ry, T hy, Vec3<T>& px, Vec3<T>& py) {
  using namespace rim_ops;
  const T kx = T(2) * hx, ky = T(2) * hy;
  const T ax = r / std::sqrt(kx * kx + r * r), ay = ry / std::sqrt(ky * ky + ry * ry);
  const T beta = b.z(), s2 = T(1) - beta * beta;
  const T x = (ax + ay * beta) / s2, y = -(ay + ax * beta) / s2;
  const T z2 = ((T(1) - x * ax) + y * ay) / s2;
  const T cab = c.y() * b.x() - c.x() * b.y();
  const T zm = std::sqrt(z2 > T(0) ? z2 : T(0));
  const T z = cab < T(0) ? -zm : zm;
  const Vec3<T> n(y * b.x() - z * b.y(), y * b.y() + z * b.x(), x + y * b.z());
  const T kn = r / std::sqrt(n.x() * n.x() + n.y() * n.y());
  const Vec3<T> d1(kn * n.x(), kn * n.y(), -kx);
  const Vec3<T> e = add(n, scale(ay, b));
  const T ke = ry / std::sqrt(dot3(e, e));
  const Vec3<T> d2 = sub(scale(-ke, e), scale(ky, b));
  const Vec3<T> ox(T(0), T(0), hx), oy = add(c, scale(hy, b));
  const Vec3<T> w0 = sub(ox, oy);
  const T aa = dot3(d1, d1), bq = dot3(d1, d2), cq = dot3(d2, d2), dd = dot3(d1, w0), ee = dot3(d2, w0);
  const T denom = aa * cq - bq * bq;
  const T tau = (bq * ee - cq * dd) / denom, sig = (aa * ee - bq * dd) / denom;
  px = add(ox, scale(tau, d1));
  py = add(oy, scale(sig, d2));
  return s2 > T(0) && z2 > T(0) && tau >= T(0) && tau <= T(1) && sig >= T(0) && sig <= T(1) &&
         dot3(sub(py, px), n) > T(0);
}

/// wide_gjk_rim_rim.inl's round_round(): X (own frame) against Y (c, b, ry, hy); keep(ok, px, py).
template <class T, class Keep>
void round_round(T r, T hx, bool xcone, const Vec3<T>& c, const Vec3<T>& b, T ry, T hy, bool ycone, bool rims,
                 const Keep& keep) {
  using namespace rim_ops;
  const T cb = dot3(c, b);
  const T sy = ycone ? T(-1) : (cb > T(0) ? T(-1) : T(1));
  const T zy = sy * hy;
  const Vec3<T> q = add(c, scale(zy, b)), nrm = scale(sy, b);
  const T zr = xcone ? -hx : (q.z() < T(0) ? -hx : hx);
  if (rims) {
    Vec3<T> px, py;
    const bool ok = rim_rim(r, zr, q, b, ry, px, py);
    keep(ok, px, py);
  }
  {
    const T zd = xcone ? -hx : (nrm.z() < T(0) ? hx : -hx);
    Vec3<T> px, py;
    const bool ok = rim_disk(r, zd, q, nrm, ry, px, py);
    keep(ok, px, py);
  }
  if (xcone) {
    const Vec3<T> apex(T(0), T(0), hx);
    keep(true, apex, solid_point(apex, c, b, ry, hy, ycone));
  }
}

/// wide_gjk_rim_rim.inl's round_segment(): X (own frame) against the segment p + z d, |z| <= hs; keep(ok, px, z).
template <class T, class Keep>
void round_segment(T r, T hx, bool cone, const Vec3<T>& p, const Vec3<T>& d, T hs, const Keep& keep) {
  using namespace rim_ops;
  const Vec3<T> o(T(0), T(0), T(0)), ez(T(0), T(0), T(1));
  for (int sg = 1; sg >= -1; sg -= 2) {
    const T z = T(sg) * hs;
    keep(true, solid_point(add(p, scale(z, d)), o, ez, r, hx, cone), z);
  }
  {
    const T zr = cone ? -hx : (p.z() < T(0) ? -hx : hx);
    Vec3<T> px;
    T along;
    const bool ok = edge_rim(r, zr, p, d, hs, px, along);
    keep(ok, px, along);
  }
  if (cone) {
    Vec3<T> px;
    T along;
    const bool ok = slant_line(r, hx, p, d, hs, px, along);
    keep(ok, px, along);
    const T za = dot3(sub(Vec3<T>(T(0), T(0), hx), p), d);
    keep(true, Vec3<T>(T(0), T(0), hx), za > hs ? hs : (za < -hs ? -hs : za));
  }
}

/// wide_gjk_rim_rim.inl's round_apart(): whether n = pb - pa separates the cores (R row-major as the lanes').
template <class T>
bool round_apart(ShapeType ta, ShapeType tb, const T* R, const Vec3<T>& t, T a0, T a1, T b0, T b1, const Vec3<T>& pa,
                 const Vec3<T>& pb) {
  const Vec3<T> n = rim_ops::sub(pb, pa);
  const auto ext = [&](ShapeType ty, T r, T h, T an, T n2) {
    const T ha = h * an;
    const T hab = ha < T(0) ? -ha : ha;
    if (ty == ShapeType::capsule) return hab;
    const T t2 = n2 - an * an;
    const T sq = r * std::sqrt(t2 > T(0) ? t2 : T(0));
    if (ty == ShapeType::cone) return ha > sq - ha ? ha : sq - ha;
    return hab + sq;
  };
  const T n2 = dot3(n, n);
  const T ea = ext(ta, a0, a1, n.z(), n2);
  const T bn = (R[2] * n.x() + R[5] * n.y()) + R[8] * n.z();
  const T eb = ext(tb, b0, b1, -bn, n2);
  const T tn = (t.x() * n.x() + t.y() * n.y()) + t.z() * n.z();
  return (tn - eb) - ea > T(0);
}

}  // namespace batchcol::test_reference
