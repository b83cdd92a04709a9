// WideGjk's closed-form start point of box-ellipsoid pairs (double distance / witness lanes).
//
// No include guard: included inside struct WideGjk (wide_gjk.inl), whose V3, real, mask and helpers it uses.
// tests/support/reference_box_ellipsoid.hpp is its scalar transcription, with the same operations in the same
// order (the lanes' answers must stay bitwise equal to the reference's).
//
// Why: GJK converges only linearly when a box's edge or vertex touches a curved surface (its support points jump
// between the edge's two ends and the ellipsoid's support chases the contact normal): close witness double
// box-ellipsoid took 18.7 iterations, 21.0 on an edge contact (56% of the row's iterations), 27.4 on a vertex (23%),
// 11.5 on a face (21%) (bench/results/history/narrowphase-sessions.md). The optimum of each feature against the
// ellipsoid has a cheap characterisation, so a few Newton steps give a point of D at the optimum up to their
// error, and GJK's first plain step certifies it (the duality-gap stop is unchanged).

/// The box (half extents h, centred, axis-aligned: its own frame) against the ellipsoid (centre c, rotation E
/// row-major with its axes as columns, radii r, in the box's frame). With Q = E diag(r^2) E^T the ellipsoid's
/// support in the unit direction m is c + Q m / sqrt(m^T Q m), its support function <c, m> + sqrt(m^T Q m).
/// Candidates, on the box's side facing the ellipsoid's centre (s = sign(c) per axis):
/// - face k: the ellipsoid's support toward the face, pb = c - s_k Q e_k / sqrt(Q_kk), with pa = clamp(pb) on
///   the face: the optimum when pb lies over the face.
/// - edge along axis k (per lane: the k whose face gap s_k c_k - sqrt(Q_kk) - h_k is the smallest, the face seen
///   side-on): the edge projects to a point and the ellipsoid to the ellipse of the 2x2 block Q2 of Q in the
///   other two axes (the block of a support metric is the projection's), so the edge-ellipsoid distance is the
///   point-ellipse distance max over theta of f = <p, m> - sqrt(m^T Q2 m), m = (cos, sin) theta, p = the
///   ellipse centre relative to the corner. kBoxEdgeNewtonSteps Newton steps on theta (wrim's rotation by dt,
///   rim_lateral()): with q = m^T Q2 m, q1 = m_perp^T Q2 m, qp = m_perp^T Q2 m_perp, the support function's
///   derivatives are h' = q1 / h, h'' = ((qp - q) - h'^2) / h (h = sqrt(q)); f' = <p, m_perp> - h', f'' =
///   -<p, m> - h''; where f'' is not negative it does not move. Start: m along Q2^-1 p (adj(Q2) p), the normal
///   where the ray from the centre toward the corner meets the ellipse. pb = the support at -m (3-D), pa = the
///   edge point clamp(pb_k).
/// - the vertex s h: the nearest ellipsoid point y = diag(r^2) (r^2 + t)^-1 p' (p' = E^T (s h - c), the
///   Lagrange condition) with t the root of S(t) = sum r_k^2 p'_k^2 / (r_k^2 + t)^2 = 1; kBoxVertexNewtonSteps
///   Newton steps from t = 0 on S^-1/2 - 1 (linear in t for a sphere, so exact there in one step): dt = S (sqrt(S)
///   - 1) / sum r_k^2 p'_k^2 / (r_k^2 + t)^3. y is then scaled onto the surface by S^-1/2 (a point of the
///   ellipsoid whatever t is).
/// Every candidate is a point of the box minus a point of the ellipsoid, hence of D; the closest one is kept
/// (NaN candidates, e.g. a centre on a corner, never are). pa, pb in the box's frame.
/// `Core`: the box itself (kBoxCore), or a box with zero extents standing for a capsule's core, the segment
/// h = (0, 0, half length) (kSegmentCore: only the edge along z, the segment itself, and its end toward the
/// ellipsoid; a face's point lies on the segment, so the segment's own candidate is never farther, and the
/// other edges have zero length: the end again), or for a sphere's core, the point h = 0
/// (kPointCore: only the vertex, the nearest ellipsoid point, exact up to the Newton steps). Why: sphere- and
/// capsule-ellipsoid pairs run GJK on the cores to convergence at the witness level, overlapping spheres and
/// capsules included (their cores are apart); the demo measured 4.3-4.7 mean iterations on them, 14% of its
/// instructions (bench/results/history/narrowphase-sessions.md, helper `demo`, 2026-11-27).
template <int Core>
AI static void box_ellipsoid_point(const real* E, const V3& c, const real* r, const real* h, V3& pa, V3& pb) {
  const real zero = splat(T(0)), one = splat(T(1)), nan = splat(std::numeric_limits<T>::quiet_NaN());
  const real rr[3] = {r[0] * r[0], r[1] * r[1], r[2] * r[2]};
  real P[9];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) P[3 * i + k] = E[3 * i + k] * rr[k];
  const auto q = [&](int i, int j) { return (P[3 * i] * E[3 * j] + P[3 * i + 1] * E[3 * j + 1]) + P[3 * i + 2] * E[3 * j + 2]; };
  const real Q[9] = {q(0, 0), q(0, 1), q(0, 2), q(0, 1), q(1, 1), q(1, 2), q(0, 2), q(1, 2), q(2, 2)};
  const real cc[3] = {c.x, c.y, c.z};
  const real s[3] = {select(c.x < zero, -one, one), select(c.y < zero, -one, one), select(c.z < zero, -one, one)};
  const auto clamp = [&](const real& v, const real& e) { return select(v > e, e, select(v < -e, -e, v)); };
  pa = pb = {nan, nan, nan};
  real best = splat(std::numeric_limits<T>::infinity());
  const auto keep = [&](const V3& qa, const V3& qb) {
    const real n2 = norm2(sub(qa, qb));
    const mask take = n2 < best;
    pa = pick(take, qa, pa);
    pb = pick(take, qb, pb);
    best = select(take, n2, best);
  };
  // Faces.
  real gap[3] = {zero, zero, zero};
  for (int k = 0; k < 3 && Core == kBoxCore; ++k) {
    const real rk = wsqrt<T>(Q[4 * k]);
    gap[k] = (s[k] * cc[k] - rk) - h[k];
    const real f = s[k] / rk;
    const V3 qb = {cc[0] - f * Q[k], cc[1] - f * Q[3 + k], cc[2] - f * Q[6 + k]};
    V3 qa = {clamp(qb.x, h[0]), clamp(qb.y, h[1]), clamp(qb.z, h[2])};
    if (k == 0) qa.x = s[0] * h[0];
    if (k == 1) qa.y = s[1] * h[1];
    if (k == 2) qa.z = s[2] * h[2];
    keep(qa, qb);
  }
  // The edge along the axis of the smallest gap (k0, k1, k2: that axis is x, y, z); (i, j) = (k + 1, k + 2) mod 3.
  // A segment's edge is z (kSegmentCore).
  const mask k0 = Core == kBoxCore ? (gap[0] <= gap[1]) & (gap[0] <= gap[2]) : splat_mask(0);
  const mask k1 = Core == kBoxCore ? ~k0 & (gap[1] <= gap[2]) : splat_mask(0);
  const mask k2 = ~(k0 | k1);
  const auto by_axis = [&](const real& v0, const real& v1, const real& v2) { return select(k0, v0, select(k1, v1, v2)); };
  const real pp[3] = {s[0] * cc[0] - h[0], s[1] * cc[1] - h[1], s[2] * cc[2] - h[2]};
  const real a = by_axis(Q[4], Q[8], Q[0]), d = by_axis(Q[8], Q[0], Q[4]);
  const real b = by_axis((s[1] * s[2]) * Q[5], (s[2] * s[0]) * Q[2], (s[0] * s[1]) * Q[1]);
  const real p0 = by_axis(pp[1], pp[2], pp[0]), p1 = by_axis(pp[2], pp[0], pp[1]);
  if (Core != kPointCore) {
    const real m0 = d * p0 - b * p1, m1 = a * p1 - b * p0;
    const real inv0 = one / wsqrt<T>(m0 * m0 + m1 * m1);
    real C = m0 * inv0, S = m1 * inv0;
    for (int it = 0; it < kBoxEdgeNewtonSteps; ++it) {
      const real Qm0 = a * C + b * S, Qm1 = b * C + d * S;
      const real qq = C * Qm0 + S * Qm1;
      const real q1 = C * Qm1 - S * Qm0;
      const real qp = S * (a * S - b * C) + C * (d * C - b * S);
      const real ih = one / wsqrt<T>(qq);
      const real h1 = q1 * ih;
      const real h2 = ((qp - qq) - h1 * h1) * ih;
      const real f1 = (C * p1 - S * p0) - h1;
      const real f2 = -(C * p0 + S * p1) - h2;
      const real dt = select(f2 < zero, -f1 / f2, zero);
      const real C1 = C - dt * S, S1 = S + dt * C;
      const real inv = one / wsqrt<T>(C1 * C1 + S1 * S1);
      C = C1 * inv;
      S = S1 * inv;
    }
    const V3 m = {by_axis(zero, s[0] * S, s[0] * C), by_axis(s[1] * C, zero, s[1] * S), by_axis(s[2] * S, s[2] * C, zero)};
    const V3 Qm = {(Q[0] * m.x + Q[1] * m.y) + Q[2] * m.z, (Q[3] * m.x + Q[4] * m.y) + Q[5] * m.z,
                   (Q[6] * m.x + Q[7] * m.y) + Q[8] * m.z};
    const real f = one / wsqrt<T>(dot(m, Qm));
    const V3 qb = {cc[0] - f * Qm.x, cc[1] - f * Qm.y, cc[2] - f * Qm.z};
    const V3 qa = {select(k0, clamp(qb.x, h[0]), s[0] * h[0]), select(k1, clamp(qb.y, h[1]), s[1] * h[1]),
                   select(k2, clamp(qb.z, h[2]), s[2] * h[2])};
    keep(qa, qb);
  }
  // The vertex.
  {
    const V3 qa = {s[0] * h[0], s[1] * h[1], s[2] * h[2]};
    const V3 v = sub(qa, c);
    real p[3], w[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = (E[k] * v.x + E[3 + k] * v.y) + E[6 + k] * v.z;
      w[k] = rr[k] * (p[k] * p[k]);
    }
    real t = zero;
    for (int it = 0; it < vertex_newton_steps(Core); ++it) {
      const real e0 = one / (rr[0] + t), e1 = one / (rr[1] + t), e2 = one / (rr[2] + t);
      const real a0 = (w[0] * e0) * e0, a1 = (w[1] * e1) * e1, a2 = (w[2] * e2) * e2;
      const real S = (a0 + a1) + a2;
      const real D1 = (a0 * e0 + a1 * e1) + a2 * e2;
      t = t + (S * (wsqrt<T>(S) - one)) / D1;
    }
    const real e0 = one / (rr[0] + t), e1 = one / (rr[1] + t), e2 = one / (rr[2] + t);
    const real S = ((w[0] * e0) * e0 + (w[1] * e1) * e1) + (w[2] * e2) * e2;
    const real f = one / wsqrt<T>(S);
    const real y[3] = {((rr[0] * p[0]) * e0) * f, ((rr[1] * p[1]) * e1) * f, ((rr[2] * p[2]) * e2) * f};
    const V3 qb = {((E[0] * y[0] + E[1] * y[1]) + E[2] * y[2]) + c.x, ((E[3] * y[0] + E[4] * y[1]) + E[5] * y[2]) + c.y,
                   ((E[6] * y[0] + E[7] * y[1]) + E[8] * y[2]) + c.z};
    keep(qa, qb);
  }
  // Only where the kept candidate's direction n = pb - pa separates the shapes (the ellipsoid's support along -n
  // beyond the box's along n: <c, n> - sqrt(n^T Q n) > sum h_k |n_k|, squared, both sides homogeneous in n):
  // overlapping pairs keep their first support point. Measured, overlap penetration double box-ellipsoid, 20000
  // pairs: without this test 20.2 -> 37.1 mean iterations (a start point near the origin slows the proof of
  // overlap and EPA's start).
  const V3 n = sub(pb, pa);
  const V3 Qn = {(Q[0] * n.x + Q[1] * n.y) + Q[2] * n.z, (Q[3] * n.x + Q[4] * n.y) + Q[5] * n.z,
                 (Q[6] * n.x + Q[7] * n.y) + Q[8] * n.z};
  const real an[3] = {select(n.x < zero, -n.x, n.x), select(n.y < zero, -n.y, n.y), select(n.z < zero, -n.z, n.z)};
  const real lhs = dot(c, n) - ((h[0] * an[0] + h[1] * an[1]) + h[2] * an[2]);
  const mask apart = (lhs > zero) & (lhs * lhs > dot(n, Qn));
  pa = pick(apart, pa, V3{nan, nan, nan});
  pb = pick(apart, pb, V3{nan, nan, nan});
}

/// box_ellipsoid_point() for W pairs of a box_ellipsoid_pair() type, A's frame: R (row-major), t: B's pose in A's
/// frame; sa, sb: the cores' sizes (a box's half extents, an ellipsoid's radii, a capsule's half length as the
/// second, kernels/shape_core.hpp; a sphere's core has none). With the ellipsoid as A, its pose in the flat
/// core's (B's) frame is (R^T, -R^T t), and the points are mapped back by R and t. Computed where the pairs are set up, W
/// at a time (WideGjkPairs' fill_slots()), as rim_candidate(). The sizes by value: passing fill_slots()'s size
/// arrays by address made it keep its sides' values in memory in every run, boolean runs included (+6
/// instructions per pair in run_certified(), boolean box-ellipsoid and box-cylinder double, callgrind AVX2).
__attribute__((noinline)) static void box_ellipsoid_candidate(ShapeType ta, ShapeType tb, const real* R, const real* t,
                                                              real a0, real a1, real a2, real b0, real b1, real b2,
                                                              V3& pa, V3& pb) {
  const real zero = splat(T(0));
  const bool a_flat = ta != ShapeType::ellipsoid;
  const ShapeType flat = a_flat ? ta : tb;
  // The flat core's half extents: a box's own, a capsule's segment along z, a sphere's point.
  const real f1 = a_flat ? a1 : b1;
  const real h[3] = {flat == ShapeType::box ? (a_flat ? a0 : b0) : zero, flat == ShapeType::box ? f1 : zero,
                     flat == ShapeType::box ? (a_flat ? a2 : b2) : (flat == ShapeType::capsule ? f1 : zero)};
  const real r[3] = {a_flat ? b0 : a0, a_flat ? b1 : a1, a_flat ? b2 : a2};
  const auto point = [&](const real* E, const V3& c, V3& qf, V3& qe) {
    if (flat == ShapeType::box) box_ellipsoid_point<kBoxCore>(E, c, r, h, qf, qe);
    else if (flat == ShapeType::capsule) box_ellipsoid_point<kSegmentCore>(E, c, r, h, qf, qe);
    else box_ellipsoid_point<kPointCore>(E, c, r, h, qf, qe);
  };
  if (a_flat) {
    point(R, V3{t[0], t[1], t[2]}, pa, pb);
    return;
  }
  const real Rt[9] = {R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]};
  const V3 c = {-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])};
  V3 qflat, qell;
  point(Rt, c, qflat, qell);
  const auto back = [&](const V3& q) {
    return V3{((R[0] * q.x + R[1] * q.y) + R[2] * q.z) + t[0], ((R[3] * q.x + R[4] * q.y) + R[5] * q.z) + t[1],
              ((R[6] * q.x + R[7] * q.y) + R[8] * q.z) + t[2]};
  };
  pa = back(qell);
  pb = back(qflat);
}
