// WideGjk's closed-form / Newton start point of cylinder-ellipsoid and cone-ellipsoid pairs (double distance /
// witness lanes).
//
// No include guard: included inside struct WideGjk (wide_gjk.inl), whose V3, real, mask and helpers it uses.
// tests/support/reference_round_ellipsoid.hpp is its scalar transcription, with the same operations in the same
// order (the lanes' answers must stay bitwise equal to the reference's).
//
// Why: GJK converges only linearly where a rim (a circle) or a cylinder's side / a cone's slant (a segment) meets a
// curved surface (its support points bisect the rim angle, or flip between the segment's ends): close witness
// double cylinder- and cone-ellipsoid took 13.3 / 14.4 mean iterations (bench, 20000 pairs), and separated cylinder- and cone-ellipsoid pairs were 12% of
// `batchcol demo`'s instructions at 7.0-7.3 iterations (bench/results/history/narrowphase-sessions.md, helper
// `demo`). Each contact feature is a smooth 1-D or 2-D maximisation of the gap over the contact normal, so a few
// Newton steps give a point of D near the optimum and GJK's first plain step certifies it (the duality-gap stop
// is unchanged).
//
// The gap along a unit normal n (from the round core X toward the ellipsoid) is g(n) = <c, n> - sqrt(n^T Q n) -
// h_X(n): the ellipsoid's lowest point along n (centre c, Q = E diag(r^2) E^T, its support function <c, m> +
// sqrt(m^T Q m)) minus X's support function h_X; the distance is the maximum of g over unit n (separated pairs), and
// its gradient is w(n) = s_E(-n) - s_X(n), the support points' difference, whose tangential part vanishes at the
// optimum (the support points are then aligned along n).

/// Newton on the unit normal n against a disk of X (radius rd at height zr on X's axis; rd = 0: a point, the cone's
/// apex): h(n) = zr n_z + rd rho (rho = |n_xy|), smooth where rho > 0, so it covers the rim contacts (the face
/// contact, n = +-e_z, is the caller's closed form: a kink of h). Riemannian Newton on the sphere (Absil, Mahony,
/// Sepulchre, "Optimization Algorithms on Matrix Manifolds", 2008, sec. 5.5 / 6.2, for a function of degree 1): the
/// Euclidean Hessians of the support functions, H_E = (Q - Qn (Qn)^T / q) / sqrt(q) (q = n^T Q n) and H_X =
/// (rd / rho^3) t t^T (t = (-n_y, n_x, 0)), have n in their kernel, so the sphere's Hessian of g is -(H_E + H_X + g
/// P) and the step solves (H_E + H_X + g+ I + n n^T) delta = P w (P = I - n n^T; g+ = max(g, 0) keeps the matrix
/// positive definite where the start overlaps; n n^T only fixes the normal direction's eigenvalue, the right-hand
/// side has no part along n), then n <- (n + delta) / |n + delta|. Start n0: the ellipsoid's normal where the ray
/// from its centre toward X's point nearest to it (x0) meets its surface, Q^-1 (c - x0) = E diag(r^-2) E^T (c -
/// x0) (box_ellipsoid_point()'s edge start in 3-D). qa = s_X(n) on the disk's rim, qb = s_E(-n) on the ellipsoid.
AI static void disk_ellipsoid(const real* E, const real* Q, const V3& c, const real* ir2, real rd, real zr, V3& qa,
                              V3& qb) {
  const real zero = splat(T(0)), one = splat(T(1));
  V3 n;
  {
    const real cr = wsqrt<T>(c.x * c.x + c.y * c.y);
    const real f = select(cr > zero, rd / cr, zero);
    const V3 v = {c.x - f * c.x, c.y - f * c.y, c.z - zr};
    const real p0 = ((E[0] * v.x + E[3] * v.y) + E[6] * v.z) * ir2[0];
    const real p1 = ((E[1] * v.x + E[4] * v.y) + E[7] * v.z) * ir2[1];
    const real p2 = ((E[2] * v.x + E[5] * v.y) + E[8] * v.z) * ir2[2];
    const V3 m = {(E[0] * p0 + E[1] * p1) + E[2] * p2, (E[3] * p0 + E[4] * p1) + E[5] * p2,
                  (E[6] * p0 + E[7] * p1) + E[8] * p2};
    n = scale(one / norm(m), m);
  }
  for (int it = 0; it < kRoundEllipsoidNewtonSteps; ++it) {
    const V3 Qn = {(Q[0] * n.x + Q[1] * n.y) + Q[2] * n.z, (Q[3] * n.x + Q[4] * n.y) + Q[5] * n.z,
                   (Q[6] * n.x + Q[7] * n.y) + Q[8] * n.z};
    const real q = dot(n, Qn);
    const real is = one / wsqrt<T>(q);
    const real rho = wsqrt<T>(n.x * n.x + n.y * n.y);
    const real ir = select(rho > zero, one / rho, zero);
    const real kx = rd * ir;
    const V3 w = {(c.x - Qn.x * is) - kx * n.x, (c.y - Qn.y * is) - kx * n.y, (c.z - Qn.z * is) - zr};
    const real g = dot(w, n);
    const V3 b = sub(w, scale(g, n));
    const real gp = select(g > zero, g, zero);
    const real iq = one / q;
    const real ka = (kx * ir) * ir;
    // M = H_E + H_X + g+ I + n n^T (symmetric).
    const real m00 = (((Q[0] - (Qn.x * Qn.x) * iq) * is + ka * (n.y * n.y)) + gp) + n.x * n.x;
    const real m11 = (((Q[4] - (Qn.y * Qn.y) * iq) * is + ka * (n.x * n.x)) + gp) + n.y * n.y;
    const real m22 = ((Q[8] - (Qn.z * Qn.z) * iq) * is + gp) + n.z * n.z;
    const real m01 = ((Q[1] - (Qn.x * Qn.y) * iq) * is - ka * (n.x * n.y)) + n.x * n.y;
    const real m02 = (Q[2] - (Qn.x * Qn.z) * iq) * is + n.x * n.z;
    const real m12 = (Q[5] - (Qn.y * Qn.z) * iq) * is + n.y * n.z;
    const real A00 = m11 * m22 - m12 * m12, A01 = m02 * m12 - m01 * m22, A02 = m01 * m12 - m02 * m11;
    const real A11 = m00 * m22 - m02 * m02, A12 = m01 * m02 - m00 * m12, A22 = m00 * m11 - m01 * m01;
    const real id = one / ((m00 * A00 + m01 * A01) + m02 * A02);
    const V3 n1 = {n.x + ((A00 * b.x + A01 * b.y) + A02 * b.z) * id, n.y + ((A01 * b.x + A11 * b.y) + A12 * b.z) * id,
                   n.z + ((A02 * b.x + A12 * b.y) + A22 * b.z) * id};
    n = scale(one / norm(n1), n1);
  }
  const V3 Qn = {(Q[0] * n.x + Q[1] * n.y) + Q[2] * n.z, (Q[3] * n.x + Q[4] * n.y) + Q[5] * n.z,
                 (Q[6] * n.x + Q[7] * n.y) + Q[8] * n.z};
  const real is = one / wsqrt<T>(dot(n, Qn));
  const real rho = wsqrt<T>(n.x * n.x + n.y * n.y);
  const real kx = select(rho > zero, rd / rho, zero);
  qa = {kx * n.x, kx * n.y, zr};
  qb = {c.x - Qn.x * is, c.y - Qn.y * is, c.z - Qn.z * is};
}

/// Newton on the angle phi of the normals m(phi) = (k cos phi, k sin phi, z0) of X's lateral surface: a cylinder's
/// side (k = 1, z0 = 0, every generator's normal is horizontal) or a cone's slant (k = 2 hy, z0 = r: normal to the
/// generator from the apex (0, 0, hy) to the rim point (r cos phi, r sin phi, -hy)). Along those normals h_X is
/// constant for the cylinder (r |m|) and <apex, m> for the cone, so the gap is, up to a constant and the factor
/// 1 / |m|, G(phi) = <c', m> - sqrt(m^T Q m) (c' = c - apex; c for the cylinder), maximised by kRoundEllipsoidSideSteps
/// Newton steps: G' = <c', m1> - <Qm, m1> / s, G'' = <c', m2> - (<Q m1, m1> + <Qm, m2>) / s + <Qm, m1>^2 / s^3 (s =
/// sqrt(m^T Q m), m1 = (-k sin, k cos, 0), m2 = (-k cos, -k sin, 0)); a step turns (C, S) by dt = -G' / G'' where
/// G'' < 0 (rim_lateral()'s turn), else it does not move. Start: (C, S) along adj(Q2) c'_xy (Q2: Q's xy block), the
/// horizontal normal of box_ellipsoid_point()'s edge start. qb = s_E(-m); qa = the generator's point nearest to qb,
/// clamped to the generator (a point of X whatever the angle).
AI static void side_ellipsoid(const real* Q, const V3& c, real r, real hy, bool cone, V3& qa, V3& qb) {
  const real zero = splat(T(0)), one = splat(T(1));
  const real k = cone ? T(2) * hy : one, z0 = cone ? r : zero;
  real C, S;
  {
    const real u0 = Q[4] * c.x - Q[1] * c.y, u1 = Q[0] * c.y - Q[1] * c.x;
    const real inv = one / wsqrt<T>(u0 * u0 + u1 * u1);
    C = u0 * inv;
    S = u1 * inv;
  }
  // Q m = C (k Q e_x) + S (k Q e_y) + z0 Q e_z; Q m1 = k (C Q e_y - S Q e_x).
  for (int it = 0; it < kRoundEllipsoidSideSteps; ++it) {
    const real kc = k * C, ks = k * S;
    const V3 m = {kc, ks, z0}, m1 = {-ks, kc, zero};
    const V3 Qm = {(Q[0] * kc + Q[1] * ks) + Q[2] * z0, (Q[3] * kc + Q[4] * ks) + Q[5] * z0,
                   (Q[6] * kc + Q[7] * ks) + Q[8] * z0};
    const V3 Qm1 = {Q[1] * kc - Q[0] * ks, Q[4] * kc - Q[3] * ks, Q[7] * kc - Q[6] * ks};
    const real is = one / wsqrt<T>(dot(m, Qm));
    const real a1 = dot(Qm, m1);
    const real cm1 = c.y * kc - c.x * ks, cm2 = -(c.x * kc + c.y * ks);
    const real qm2 = -(Qm.x * kc + Qm.y * ks);
    const real g1 = cm1 - a1 * is;
    const real g2 = (cm2 - (dot(Qm1, m1) + qm2) * is) + ((a1 * a1) * is) * (is * is);
    const real dt = select(g2 < zero, -g1 / g2, zero);
    const real C1 = C - dt * S, S1 = S + dt * C;
    const real inv = one / wsqrt<T>(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  const real kc = k * C, ks = k * S;
  const V3 Qm = {(Q[0] * kc + Q[1] * ks) + Q[2] * z0, (Q[3] * kc + Q[4] * ks) + Q[5] * z0,
                 (Q[6] * kc + Q[7] * ks) + Q[8] * z0};
  const real is = one / wsqrt<T>((kc * Qm.x + ks * Qm.y) + z0 * Qm.z);
  qb = {c.x - Qm.x * is, c.y - Qm.y * is, c.z - Qm.z * is};
  if (cone) {  // the generator apex + tau (r C, r S, -2 hy), tau in [0, 1]
    const V3 gd = {r * C, r * S, -k};
    const real tau = ((gd.x * qb.x + gd.y * qb.y) + gd.z * (qb.z - hy)) / dot(gd, gd);
    const real tc = select(tau > one, one, select(tau < zero, zero, tau));
    qa = {tc * gd.x, tc * gd.y, hy + tc * gd.z};
  } else {
    qa = {r * C, r * S, select(qb.z > hy, hy, select(qb.z < -hy, -hy, qb.z))};
  }
}

/// The round core X (a cylinder, or with `cone` a cone: apex at (0, 0, hy), base rim at height -hy) of radius r and
/// half-height hy, in its own frame, against the ellipsoid (centre c, rotation E row-major with its axes as
/// columns, radii rad). Candidates: the cap (a cylinder's facing one, a cone's base) seen face-on (n = +-e_z: the
/// ellipsoid's support there, qa its projection onto the disk); the facing rim (disk_ellipsoid()); a cone's apex
/// (disk_ellipsoid() with radius 0); the side or slant (side_ellipsoid()). Every candidate is a point of X minus a
/// point of the ellipsoid, hence of D; the closest one is kept (NaN candidates never are). pa, pb in X's frame.
AI static void round_ellipsoid_point(const real* E, const V3& c, const real* rad, real r, real hy, bool cone, V3& pa,
                                     V3& pb) {
  const real zero = splat(T(0)), one = splat(T(1)), nan = splat(std::numeric_limits<T>::quiet_NaN());
  const real rr[3] = {rad[0] * rad[0], rad[1] * rad[1], rad[2] * rad[2]};
  const real ir2[3] = {one / rr[0], one / rr[1], one / rr[2]};
  real P[9];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) P[3 * i + k] = E[3 * i + k] * rr[k];
  const auto q = [&](int i, int j) { return (P[3 * i] * E[3 * j] + P[3 * i + 1] * E[3 * j + 1]) + P[3 * i + 2] * E[3 * j + 2]; };
  const real Q[9] = {q(0, 0), q(0, 1), q(0, 2), q(0, 1), q(1, 1), q(1, 2), q(0, 2), q(1, 2), q(2, 2)};
  pa = pb = {nan, nan, nan};
  real best = splat(std::numeric_limits<T>::infinity());
  const auto keep = [&](const V3& qa, const V3& qb) {
    const real n2 = norm2(sub(qa, qb));
    const mask take = n2 < best;
    pa = pick(take, qa, pa);
    pb = pick(take, qb, pb);
    best = select(take, n2, best);
  };
  const real zr = cone ? -hy : select(c.z < zero, -hy, hy);
  {  // the cap face-on: n = sign(zr) e_z, the ellipsoid's support at -n, its projection onto the disk
    const real sz = cone ? -one : select(c.z < zero, -one, one);
    const real f = sz / wsqrt<T>(Q[8]);
    const V3 qb = {c.x - f * Q[2], c.y - f * Q[5], c.z - f * Q[8]};
    const real rho = wsqrt<T>(qb.x * qb.x + qb.y * qb.y);
    const real k = select(rho > r, r / rho, one);
    keep(V3{k * qb.x, k * qb.y, zr}, qb);
  }
  {
    V3 qa, qb;
    disk_ellipsoid(E, Q, c, ir2, r, zr, qa, qb);
    keep(qa, qb);
    if (cone) {
      disk_ellipsoid(E, Q, c, ir2, zero, hy, qa, qb);
      keep(qa, qb);
    }
    side_ellipsoid(Q, c, r, hy, cone, qa, qb);
    keep(qa, qb);
  }
  // Only where the kept candidate's direction n = pb - pa separates the shapes (the ellipsoid's lowest point along n,
  // <c, n> - sqrt(n^T Q n), beyond X's support h_X(n) = hy |n_z| + r |n_xy| for a cylinder, max(hy n_z, r |n_xy| -
  // hy n_z) for a cone; squared, both sides homogeneous in n): overlapping pairs keep their first support point (a
  // start near the origin slows their proof of overlap and EPA's start, box_ellipsoid_point()'s note).
  const V3 n = sub(pb, pa);
  const V3 Qn = {(Q[0] * n.x + Q[1] * n.y) + Q[2] * n.z, (Q[3] * n.x + Q[4] * n.y) + Q[5] * n.z,
                 (Q[6] * n.x + Q[7] * n.y) + Q[8] * n.z};
  const real hz = hy * n.z;
  const real rs = r * wsqrt<T>(n.x * n.x + n.y * n.y);
  const real ext = cone ? select(hz > rs - hz, hz, rs - hz) : select(hz < zero, -hz, hz) + rs;
  const real lhs = dot(c, n) - ext;
  const mask apart = (lhs > zero) & (lhs * lhs > dot(n, Qn));
  pa = pick(apart, pa, V3{nan, nan, nan});
  pb = pick(apart, pb, V3{nan, nan, nan});
}

/// round_ellipsoid_point() for W pairs of a round_ellipsoid_pair() type, A's frame: R (row-major), t: B's pose in A's
/// frame; sizes: a cylinder's or cone's radius and half-height, an ellipsoid's radii (kernels/shape_core.hpp). With
/// the ellipsoid as A, X's pose in the ellipsoid's frame is (R^T, -R^T t): the ellipsoid's pose in X's frame is then
/// (R^T, -R^T t), i.e. E = R^T, c = -R^T t, and the points are mapped back by R and t. Computed where the pairs are set
/// up, W at a time (WideGjkPairs' fill_slots()), as box_ellipsoid_candidate(); sizes by value (its note).
__attribute__((noinline)) static void round_ellipsoid_candidate(ShapeType ta, ShapeType tb, const real* R,
                                                                const real* t, real a0, real a1, real a2, real b0,
                                                                real b1, real b2, V3& pa, V3& pb) {
  const bool cone = ta == ShapeType::cone || tb == ShapeType::cone;
  if (ta != ShapeType::ellipsoid) {
    const real rad[3] = {b0, b1, b2};
    round_ellipsoid_point(R, V3{t[0], t[1], t[2]}, rad, a0, a1, cone, pa, pb);
    return;
  }
  const real rad[3] = {a0, a1, a2};
  const real Rt[9] = {R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]};
  const V3 c = {-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])};
  V3 qround, qell;
  round_ellipsoid_point(Rt, c, rad, b0, b1, cone, qround, qell);
  const auto back = [&](const V3& q) {
    return V3{((R[0] * q.x + R[1] * q.y) + R[2] * q.z) + t[0], ((R[3] * q.x + R[4] * q.y) + R[5] * q.z) + t[1],
              ((R[6] * q.x + R[7] * q.y) + R[8] * q.z) + t[2]};
  };
  pa = back(qell);
  pb = back(qround);
}
