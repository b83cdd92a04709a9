// WideGjk's closed-form start point of box-cylinder and box-cone pairs (double distance / witness lanes).
//
// No include guard: included inside struct WideGjk (wide_gjk.inl), whose V3, real, mask and helpers it uses.
// tests/support/reference_box_round.hpp is its scalar transcription, with the same operations in the same order
// (the lanes' answers must stay bitwise equal to the reference's).
//
// Why: GJK converges only linearly where a box edge or vertex meets a rim or a curved side (its support points
// bisect the rim angle, or flip between the box edge's ends): close witness double box-cylinder took 13.6 mean
// iterations, 19.4 where a box edge meets the rim (35% of the row's iterations), 10.5 face vs rim (22%), 10.9
// edge vs side (21%), 19.6 vertex vs side (17%) (bench/results/history/narrowphase-sessions.md, wcurve). Each of
// these contacts has a closed form or a 1-D Newton problem; the closest candidate is a point of D near the optimum
// and GJK's first plain step certifies it (the duality-gap stop is unchanged) or goes on from it.

/// The box edge (the line p + z d, |z| <= hk, d unit) against the rim of radius r at height zr, in the round core's
/// frame: the rim point px(theta) = (r cos theta, r sin theta, zr) nearest to the line, its foot's parameter z on the
/// line (`along`), and `ok` where the foot is on the edge. The caller puts the foot on the box as the box's own p0 +
/// z e_k, exactly on the edge (mapped back from this frame it would be off the box by a few ulps). The squared distance to the line phi = |v|^2 - <v, d>^2 (v = px - p) is,
/// up to constants, f = <2 r w, m> - (r <d, m> + <w, d>)^2 (m = (cos, sin) theta, w = (0, 0, zr) - p): the best of
/// kEdgeRimSamples angles (opposite angles share the products), then kEdgeRimNewtonSteps Newton steps on theta
/// (rim_lateral()'s, for a line: g = phi' / 2, h = phi'' / 2, a turn by dt where h > 0).
AI static void edge_rim(real r, real zr, const V3& p, const V3& d, real hk, V3& px, real& along, mask& ok) {
  const real zero = splat(T(0)), one = splat(T(1));
  const V3 w = {-p.x, -p.y, zr - p.z};
  const real tr = T(2) * r;
  const real twx = tr * w.x, twy = tr * w.y, rdx = r * d.x, rdy = r * d.y, wd = dot(w, d);
  real best = splat(std::numeric_limits<T>::infinity()), C = one, S = zero;
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const real cj = splat(T(kEdgeRimCos[j])), sj = splat(T(kEdgeRimSin[j]));
    const real A = cj * twx + sj * twy, B = cj * rdx + sj * rdy;
    const real up = wd + B, dn = wd - B;
    const real fp = A - up * up, fm = (-A) - dn * dn;
    mask take = fp < best;
    best = select(take, fp, best);
    C = select(take, cj, C);
    S = select(take, sj, S);
    take = fm < best;
    best = select(take, fm, best);
    C = select(take, -cj, C);
    S = select(take, -sj, S);
  }
  for (int it = 0; it < kEdgeRimNewtonSteps; ++it) {
    const V3 v = {r * C - p.x, r * S - p.y, zr - p.z};
    const V3 v1 = {-(r * S), r * C, zero}, v2 = {-(r * C), -(r * S), zero};
    const real vb = dot(v, d), v1b = dot(v1, d), v2b = dot(v2, d);
    const real g = dot(v, v1) - vb * v1b;
    const real h = (dot(v1, v1) + dot(v, v2)) - (v1b * v1b + vb * v2b);
    const real dt = select(h > zero, -g / h, zero);
    const real C1 = C - dt * S, S1 = S + dt * C;
    const real inv = one / wsqrt<T>(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  px = {r * C, r * S, zr};
  along = dot(sub(px, p), d);
  ok &= (along <= hk) & (along >= -hk);
}

/// The box (half extents h, centred, axis-aligned: its own frame) against the round core Y (a cylinder, or with
/// `cone` a cone: apex at c + hy b, base rim at c - hy b) of radius r and half-height hy, whose pose in the box's
/// frame is (Rr row-major, c): its unit axis b = Rr e_z. Candidates, on the box's side facing Y's centre (s =
/// sign(c) per axis):
/// - face k: Y's support toward the face, pb = support(-s_k e_k), pa = clamp(pb) on the face (the optimum when pb
///   lies over the face; a cylinder's cap seen face-on gives its centre).
/// - the 3 edges along axis k at s_i h_i, s_j h_j (one, by the smallest face gap as box-ellipsoid's start chooses,
///   left close box-cylinder edge-side contacts at 3.7 mean iterations, all 3 at 1.6): against the rim facing the
///   edge's centre (a cone: its base rim) by edge_rim() (in Y's frame: Newton on the rim angle from the best of a
///   few samples, valid where the foot is interior); a cylinder also against its side (the edge's and the axis's
///   lines' closest points, both interior, offset by r along their difference: the side is the axis segment's
///   offset surface there); a cone also against its slant: the plane tangent along the generator at angle phi,
///   normal (2 hy cos phi, 2 hy sin phi, r) in Y's frame, is parallel to the edge where <d, normal> = 0 (d the
///   edge's direction: a closed form, two roots, the one whose plane lies farther from the edge separates), and
///   the closest points of the edge's line and the generator, both interior, are the optimum.
/// - the vertex s h against its nearest point of solid Y (a cylinder: the axial coordinate and the radius
///   clamped; a cone: in the (rho, z) half-plane the slant's point at the clamped projection, or below the base
///   the base disc's): one closed form for the side, the rim and the cap.
/// - a cone's apex against its nearest box point, clamp(apex) (apex vs face, edge or vertex).
/// Every candidate is a point of the box minus a point of Y, hence of D; the closest one is kept (NaN candidates,
/// e.g. an edge parallel to the axis, never are). pa, pb in the box's frame.
AI static void box_round_point(const real* Rr, const V3& c, real r, real hy, bool cone, const real* h, V3& pa, V3& pb) {
  const real zero = splat(T(0)), one = splat(T(1)), nan = splat(std::numeric_limits<T>::quiet_NaN());
  const V3 b = {Rr[2], Rr[5], Rr[8]};
  const real s[3] = {select(c.x < zero, -one, one), select(c.y < zero, -one, one), select(c.z < zero, -one, one)};
  const auto clamp = [&](const real& v, const real& e) { return select(v > e, e, select(v < -e, -e, v)); };
  pa = pb = {nan, nan, nan};
  real best = splat(std::numeric_limits<T>::infinity());
  const auto keep = [&](mask ok, const V3& qa, const V3& qb) {
    const real n2 = norm2(sub(qa, qb));
    const mask take = ok & (n2 < best);
    pa = pick(take, qa, pa);
    pb = pick(take, qb, pb);
    best = select(take, n2, best);
  };
  const mask all = splat_mask(-1);
  // Y's points are formed in Y's frame, where its axis is exactly e_z, and mapped back by Rr, c: formed in the box's
  // frame, a radial direction (u - <u, b> b over its length) is rounding noise where u is nearly axial, with an axial
  // part that put the point up to r beyond a cap, off Y (a cap facing a box face: 0.047 for a true 0.096 in
  // ReferenceBatch.QueryMatchesIndependentReferenceOn3000MixedPairs).
  const auto back = [&](const V3& q) {
    return V3{((Rr[0] * q.x + Rr[1] * q.y) + Rr[2] * q.z) + c.x, ((Rr[3] * q.x + Rr[4] * q.y) + Rr[5] * q.z) + c.y,
              ((Rr[6] * q.x + Rr[7] * q.y) + Rr[8] * q.z) + c.z};
  };
  // Faces: Y's support along u = -s_k e_k, in Y's frame d = -s_k (row k of Rr), as wide_gjk.inl's support().
  for (int k = 0; k < 3; ++k) {
    const real ms = -s[k];
    const V3 d = {ms * Rr[3 * k], ms * Rr[3 * k + 1], ms * Rr[3 * k + 2]};
    const real rho = wsqrt<T>(d.x * d.x + d.y * d.y);
    const real kf = select(rho > zero, r / rho, zero);
    V3 sy;
    if (cone) {
      const mask apex = hy * d.z >= (-hy) * d.z + r * rho;
      sy = pick(apex, V3{zero, zero, hy}, V3{d.x * kf, d.y * kf, -hy});
    } else {
      sy = {d.x * kf, d.y * kf, select(d.z < zero, -hy, hy)};
    }
    const V3 qb = back(sy);
    V3 qa = {clamp(qb.x, h[0]), clamp(qb.y, h[1]), clamp(qb.z, h[2])};
    if (k == 0) qa.x = s[0] * h[0];
    if (k == 1) qa.y = s[1] * h[1];
    if (k == 2) qa.z = s[2] * h[2];
    keep(all, qa, qb);
  }
  for (int k = 0; k < 3; ++k) {  // the edges along x, y, z on the side facing Y's centre
    real p0a[3] = {s[0] * h[0], s[1] * h[1], s[2] * h[2]}, da[3] = {zero, zero, zero};
    p0a[k] = zero;
    da[k] = one;
    const V3 p0 = {p0a[0], p0a[1], p0a[2]}, dir = {da[0], da[1], da[2]};
    const real hk = h[k];
    const V3 v = sub(p0, c);
    // In Y's frame: the edge's centre Rr^T v, its direction Rr^T e_k (row k of Rr).
    const V3 pr = {(Rr[0] * v.x + Rr[3] * v.y) + Rr[6] * v.z, (Rr[1] * v.x + Rr[4] * v.y) + Rr[7] * v.z,
                   (Rr[2] * v.x + Rr[5] * v.y) + Rr[8] * v.z};
    const V3 dr = {Rr[3 * k], Rr[3 * k + 1], Rr[3 * k + 2]};
    {  // edge vs rim
      const real zr = cone ? -hy : select(pr.z < zero, -hy, hy);
      V3 px;
      real along;
      mask ok = all;
      edge_rim(r, zr, pr, dr, hk, px, along, ok);
      keep(ok, add(p0, scale(along, dir)), back(px));
      if (cone) {  // edge vs slant: the generator whose tangent plane is parallel to the edge (in Y's frame)
        const real kr = T(2) * hy;
        const real a2 = dr.x * dr.x + dr.y * dr.y;
        const real kap = -(r * dr.z) / kr;
        const real disc = a2 - kap * kap;
        const real root = wsqrt<T>(select(disc > zero, disc, zero));
        const real Cp = (kap * dr.x - root * dr.y) / a2, Sp = (kap * dr.y + root * dr.x) / a2;
        const real Cm = (kap * dr.x + root * dr.y) / a2, Sm = (kap * dr.y - root * dr.x) / a2;
        const real zo = pr.z - hy;
        const real gp = kr * (Cp * pr.x + Sp * pr.y) + r * zo, gm = kr * (Cm * pr.x + Sm * pr.y) + r * zo;
        const mask plus = gp >= gm;
        const real C = select(plus, Cp, Cm), S = select(plus, Sp, Sm), g = select(plus, gp, gm);
        const V3 gd = {r * C, r * S, -kr}, w0 = {pr.x, pr.y, zo};
        const real aa = dot(dr, dr), bq = dot(dr, gd), cq = dot(gd, gd), dd = dot(dr, w0), ee = dot(gd, w0);
        const real denom = aa * cq - bq * bq;
        const real se = (bq * ee - cq * dd) / denom, tau = (aa * ee - bq * dd) / denom;
        const mask ok2 = (disc > zero) & (g > zero) & (tau >= zero) & (tau <= one) & (se >= -hk) & (se <= hk);
        const V3 qx = {tau * gd.x, tau * gd.y, hy + tau * gd.z};
        keep(ok2, add(p0, scale(se, dir)), back(qx));  // the edge's point on the box, as edge_rim()'s
      }
    }
    if (!cone) {  // edge vs side: the edge's point closest to the axis line (Ericson's closest points of two lines)
      const real bq = dr.z, d1 = dot(dr, pr);
      const real se = (bq * pr.z - d1) / (one - bq * bq);
      const V3 q = add(pr, scale(se, dr));
      const real rho = wsqrt<T>(q.x * q.x + q.y * q.y);
      const real f = r / rho;
      const mask ok = (se <= hk) & (se >= -hk) & (q.z <= hy) & (q.z >= -hy) & (rho > r);
      keep(ok, add(p0, scale(se, dir)), back(V3{f * q.x, f * q.y, q.z}));
    }
  }
  {  // the vertex, in Y's frame
    const V3 qa = {s[0] * h[0], s[1] * h[1], s[2] * h[2]};
    const V3 w = sub(qa, c);
    const V3 wy = {(Rr[0] * w.x + Rr[3] * w.y) + Rr[6] * w.z, (Rr[1] * w.x + Rr[4] * w.y) + Rr[7] * w.z,
                   (Rr[2] * w.x + Rr[5] * w.y) + Rr[8] * w.z};
    const real z = wy.z;
    const real rho = wsqrt<T>(wy.x * wy.x + wy.y * wy.y);
    real zq, fr;
    if (cone) {  // the slant from (rho, z) = (0, hy) to (r, -hy), at sg of its length (rim_lateral()'s foot)
      const real kr = T(2) * hy;
      const real sg = (rho * r - kr * (z - hy)) / (r * r + kr * kr);
      const real sgc = select(sg > one, one, select(sg < zero, zero, sg));
      const mask below = z < -hy;
      zq = select(below, -hy, hy - kr * sgc);
      fr = select(below, select(rho > r, r, rho), sgc * r);
    } else {
      zq = clamp(z, hy);
      fr = select(rho > r, r, rho);
    }
    const real f = select(rho > zero, fr / rho, zero);
    keep(all, qa, back(V3{f * wy.x, f * wy.y, zq}));
  }
  if (cone) {  // the apex
    const V3 qb = add(c, scale(hy, b));
    keep(all, V3{clamp(qb.x, h[0]), clamp(qb.y, h[1]), clamp(qb.z, h[2])}, qb);
  }
  // Only where the kept candidate's direction n = pb - pa separates the shapes (min over Y of <y, n> = <c, n> -
  // ext, ext = hy |<b, n>| + r sqrt(|n|^2 - <b, n>^2) for a cylinder, max(-hy <b, n>, hy <b, n> + r sqrt(..)) for
  // a cone, beyond the box's max sum h_k |n_k|): overlapping pairs keep their first support point (a start near
  // the origin slows their proof of overlap and EPA's start: box-ellipsoid's overlap penetration took 20.2 -> 37.1
  // mean iterations without this test).
  const V3 n = sub(pb, pa);
  const real bn = dot(b, n);
  const real t2 = norm2(n) - bn * bn;
  const real sq = r * wsqrt<T>(select(t2 > zero, t2, zero));
  const real hb = hy * bn;
  const real ext = cone ? select(-hb > hb + sq, -hb, hb + sq) : select(hb < zero, -hb, hb) + sq;
  const real an[3] = {select(n.x < zero, -n.x, n.x), select(n.y < zero, -n.y, n.y), select(n.z < zero, -n.z, n.z)};
  const mask apart = (dot(c, n) - ext) - ((h[0] * an[0] + h[1] * an[1]) + h[2] * an[2]) > zero;
  pa = pick(apart, pa, V3{nan, nan, nan});
  pb = pick(apart, pb, V3{nan, nan, nan});
}

/// box_round_point() for W pairs of a box_round_pair() type, A's frame: R (row-major), t: B's pose in A's frame;
/// sa, sb: the cores' sizes (a box's half extents; a cylinder's or cone's radius and half-height). With the box as
/// B, Y's pose in B's frame is (R^T, -R^T t), and the points are mapped back by R and t. Computed where the pairs
/// are set up, W at a time (WideGjkPairs' fill_slots()), as box_ellipsoid_candidate(); sizes by value (its note).
__attribute__((noinline)) static void box_round_candidate(ShapeType ta, ShapeType tb, const real* R, const real* t,
                                                          real a0, real a1, real a2, real b0, real b1, real b2, V3& pa,
                                                          V3& pb) {
  const bool cone = ta == ShapeType::cone || tb == ShapeType::cone;
  if (ta == ShapeType::box) {
    const real h[3] = {a0, a1, a2};
    box_round_point(R, V3{t[0], t[1], t[2]}, b0, b1, cone, h, pa, pb);
    return;
  }
  const real h[3] = {b0, b1, b2};
  const real Rt[9] = {R[0], R[3], R[6], R[1], R[4], R[7], R[2], R[5], R[8]};
  const V3 c = {-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])};
  V3 qbox, qround;
  box_round_point(Rt, c, a0, a1, cone, h, qbox, qround);
  const auto back = [&](const V3& q) {
    return V3{((R[0] * q.x + R[1] * q.y) + R[2] * q.z) + t[0], ((R[3] * q.x + R[4] * q.y) + R[5] * q.z) + t[1],
              ((R[6] * q.x + R[7] * q.y) + R[8] * q.z) + t[2]};
  };
  pa = back(qround);
  pb = back(qbox);
}
