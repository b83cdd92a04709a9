// WideGjk's closed-form start candidates of cylinder / cone / capsule pairs beyond rim_lateral()'s rim-vs-side
// contacts (double distance / witness lanes; rim_candidate() in wide_gjk.inl calls them): rim vs rim, rim vs cap
// disc, a cone's apex vs the other solid, and a capsule's segment (its ends, its line) vs a cylinder or cone.
//
// No include guard: included inside struct WideGjk (wide_gjk.inl), whose V3, real, mask and helpers it uses.
// tests/support/reference_rim_rim.hpp is its scalar transcription, with the same operations in the same order
// (the lanes' answers must stay bitwise equal to the reference's).
//
// Why: GJK's support points on a rim bisect the rim angle (a linear rate of 1/2, rim_lateral()'s note), and where
// no candidate covers the contact the pair pays it: close witness double (main 7c8cd99, 20000 pairs, contacts
// classified from the witness points) cylinder-cylinder rim-rim 26.6 mean iterations (50% of the row's), cap-rim /
// rim-cap 12.1 (29%); cylinder-cone rim-rim 26.5 (27%), side-apex 19.6 (10%), cap-rim / rim-base 12.1 (14%);
// cone-cone rim-rim 26.3 (21%), apex-slant 14.1 (15%), base-rim 12.2 (10%); capsule-cone segment end vs slant 7.1
// (43%), end vs rim 7.9 (30%), segment vs slant 6.2 (16%); capsule-cylinder end vs rim 7.9 (66%)
// (bench/results/history/narrowphase-sessions.md, rr). Each of these is a closed form or a 1-D Newton problem.

/// The point of solid Y (centre c, unit axis b, radius ry, half-height hy; a cone: apex c + hy b, base rim at c -
/// hy b; else a cylinder) nearest to the point w outside it, all in one frame. In Y's (rho, z) half-plane: a
/// cylinder's clamped coordinates; a cone's slant point at the clamped projection on the slant (wide_gjk.inl's
/// rim_lateral() foot), or below the base the base disc's point (wide_gjk_box_round.inl's vertex candidate).
AI static V3 solid_point(const V3& w, const V3& c, const V3& b, real ry, real hy, bool cone) {
  const real zero = splat(T(0)), one = splat(T(1));
  const V3 v = sub(w, c);
  const real z = dot(v, b);
  const V3 e = sub(v, scale(z, b));
  const real rho = norm(e);
  real zq, fr;
  if (cone) {
    const real kr = T(2) * hy;
    const real sg = (rho * ry - kr * (z - hy)) / (ry * ry + kr * kr);
    const real sgc = select(sg > one, one, select(sg < zero, zero, sg));
    const mask below = z < -hy;
    zq = select(below, -hy, hy - kr * sgc);
    fr = select(below, select(rho > ry, ry, rho), sgc * ry);
  } else {
    zq = select(z > hy, hy, select(z < -hy, -hy, z));
    fr = select(rho > ry, ry, rho);
  }
  const real f = select(rho > zero, fr / rho, zero);
  return add(add(c, scale(zq, b)), scale(f, e));
}

/// rim_lateral()'s start angle (C, S): X's rim (radius r at height zr, X's frame) against Y's lateral surface
/// (centre c, unit axis b, radius ry, half-height hy; `cone`, else a cylinder). The minimised function (a
/// cylinder's phi = rho^2, a cone's 2 hy rho + ry <v, b>, rim_lateral()'s; v = px - c, rho its distance to Y's axis)
/// has two minima on the circle, as a line's distance, and from the axis point nearest to the rim's centre Newton
/// found the far one on many contacts: close witness double (20000 pairs, 7c8cd99 + rr) cylinder-cone's rim-slant
/// contacts took 8.1 mean iterations (74% of the row's), cone-cone's rim-slant / slant-rim 7.2 / 5.9,
/// cylinder-cylinder's rim-side / side-rim 3.3 / 2.3. So (C, S) is the best of a few sampled angles. With w = (0,
/// 0, zr) - c and m = (cos, sin, 0), phi(m) = K + D1 - B^2: K = |w|^2 + r^2 - <w, b>^2, D1 = 2 r <w - <w, b> b, m>,
/// B = r <m, b>, and the opposite angle -m flips the signs of D1 and B only (a cone's constant ry <w, b> is left
/// out). A cylinder's better of m and -m is then -|D1| - B^2: one compare and four selects per pair of angles
/// instead of two and six, as the samples cost more than they saved on distant pairs, which took ~1.1 iterations
/// already (distant witness double cylinder-cylinder +4.7% instructions, callgrind AVX2). The same choices as
/// the old form's on the bench's pairs (the scalar reference's iterations identical); 8 angles instead of
/// kEdgeRimSamples took close cylinder-cylinder 1.30 -> 1.40 mean iterations
/// (bench/results/history/narrowphase-sessions.md, cone and cyl).
AI static void lateral_start(real r, real zr, const V3& c, const V3& b, real ry, real hy, bool cone, real& C,
                             real& S) {
  const real zero = splat(T(0)), one = splat(T(1));
  const V3 w = {-c.x, -c.y, zr - c.z};
  const real tr = T(2) * r, kr = T(2) * hy;
  const real wb = dot(w, b);
  const real dx = tr * (w.x - wb * b.x), dy = tr * (w.y - wb * b.y), rbx = r * b.x, rby = r * b.y;
  if (!cone) {  // maximise |D1| + B^2 over the sampled pairs of angles, then take the sign that makes D1 negative
    real best = splat(-std::numeric_limits<T>::infinity()), Cb = one, Sb = zero, Db = zero;
    for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
      const real cj = splat(T(kEdgeRimCos[j])), sj = splat(T(kEdgeRimSin[j]));
      const real D1 = cj * dx + sj * dy, B = cj * rbx + sj * rby;
      const real g = wmax(D1, -D1) + B * B;
      const mask take = g > best;
      best = select(take, g, best);
      Cb = select(take, cj, Cb);
      Sb = select(take, sj, Sb);
      Db = select(take, D1, Db);
    }
    const mask flip = Db > zero;
    C = select(flip, -Cb, Cb);
    S = select(flip, -Sb, Sb);
    return;
  }
  const real K = (norm2(w) + r * r) - wb * wb;
  real best = splat(std::numeric_limits<T>::infinity());
  C = one;
  S = zero;
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const real cj = splat(T(kEdgeRimCos[j])), sj = splat(T(kEdgeRimSin[j]));
    const real D1 = cj * dx + sj * dy, B = cj * rbx + sj * rby;
    const real t0 = K - B * B;
    const real pp = t0 + D1, pm = t0 - D1;
    const real fp = kr * wsqrt<T>(select(pp > zero, pp, zero)) + ry * B;
    const real fm = kr * wsqrt<T>(select(pm > zero, pm, zero)) - ry * B;
    mask take = fp < best;
    best = select(take, fp, best);
    C = select(take, cj, C);
    S = select(take, sj, S);
    take = fm < best;
    best = select(take, fm, best);
    C = select(take, -cj, C);
    S = select(take, -sj, S);
  }
}

/// X's rim (radius r at height zr on X's axis, X's frame) against Y's rim (centre q, unit axis b, radius ry): the
/// rim point px(theta) = (r cos theta, r sin theta, zr) nearest to Y's circle and py, its nearest point of that
/// circle (the radial direction of px - q in Y's rim plane, scaled to ry). With v = px - q, vb = <v, b>, rho =
/// sqrt(|v|^2 - vb^2), the squared distance to the circle is (rho - ry)^2 + vb^2 = |v|^2 - 2 ry rho + ry^2:
/// f / 2 = |v|^2 / 2 - ry rho, f' / 2 = <v, v'> - ry rho', f'' / 2 = |v'|^2 + <v, v''> - ry rho'' (rho', rho'' as in
/// rim_lateral()). It has two minima on the circle (as a line's distance, edge_rim()'s note), so theta starts at the
/// best of kEdgeRimSamples angles (opposite angles share the products: |v|^2 = |w|^2 + r^2 +- 2 r <w, m>, vb = <w,
/// b> +- r <m, b>, w = (0, 0, zr) - q, m = (cos, sin, 0)), then kRimRimNewtonSteps Newton steps (rim_lateral()'s
/// turn, where the second derivative is positive). ok: rho > 0 (py defined).
AI static void rim_rim(real r, real zr, const V3& q, const V3& b, real ry, V3& px, V3& py, mask& ok) {
  const real zero = splat(T(0)), one = splat(T(1));
  const V3 w = {-q.x, -q.y, zr - q.z};
  const real tr = T(2) * r, ty = T(2) * ry;
  const real twx = tr * w.x, twy = tr * w.y, rbx = r * b.x, rby = r * b.y;
  const real wb = dot(w, b), base = norm2(w) + r * r;
  real best = splat(std::numeric_limits<T>::infinity()), C = one, S = zero;
  for (int j = 0; j < kEdgeRimSamples / 2; ++j) {
    const real cj = splat(T(kEdgeRimCos[j])), sj = splat(T(kEdgeRimSin[j]));
    const real A = cj * twx + sj * twy, B = cj * rbx + sj * rby;
    const real up = wb + B, dn = wb - B;
    const real pp = (base + A) - up * up, pm = (base - A) - dn * dn;
    const real fp = A - ty * wsqrt<T>(select(pp > zero, pp, zero));
    const real fm = (-A) - ty * wsqrt<T>(select(pm > zero, pm, zero));
    mask take = fp < best;
    best = select(take, fp, best);
    C = select(take, cj, C);
    S = select(take, sj, S);
    take = fm < best;
    best = select(take, fm, best);
    C = select(take, -cj, C);
    S = select(take, -sj, S);
  }
  for (int it = 0; it < kRimRimNewtonSteps; ++it) {
    const V3 v = {r * C - q.x, r * S - q.y, zr - q.z};
    const V3 v1 = {-(r * S), r * C, zero}, v2 = {-(r * C), -(r * S), zero};
    const real vb = dot(v, b), v1b = dot(v1, b), v2b = dot(v2, b);
    const real vv1 = dot(v, v1), hh = dot(v1, v1) + dot(v, v2);
    const real g = vv1 - vb * v1b;
    const real h = hh - (v1b * v1b + vb * v2b);
    const real ir = one / wsqrt<T>(dot(v, v) - vb * vb);
    const real r1 = g * ir, r2 = (h - r1 * r1) * ir;
    const real f1 = vv1 - ry * r1, f2 = hh - ry * r2;
    const real dt = select(f2 > zero, -f1 / f2, zero);
    const real C1 = C - dt * S, S1 = S + dt * C;
    const real inv = one / wsqrt<T>(C1 * C1 + S1 * S1);
    C = C1 * inv;
    S = S1 * inv;
  }
  px = {r * C, r * S, zr};
  const V3 v = sub(px, q);
  const V3 e = sub(v, scale(dot(v, b), b));
  const real rho = norm(e);
  ok &= rho > zero;
  py = add(q, scale(ry / rho, e));
}

/// X's rim (radius r at height zr, X's frame) against Y's cap disc (centre q, unit normal nrm facing X, radius
/// ry): the rim point deepest along -nrm, px = (r m, zr) with m = -(nrm.x, nrm.y) / |.|, and its foot py on the
/// cap's plane; ok where px is on the outer side and the foot inside the disc (then the pair touches there: rim
/// against face, a closed form).
AI static void rim_disk(real r, real zr, const V3& q, const V3& nrm, real ry, V3& px, V3& py, mask& ok) {
  const real zero = splat(T(0));
  const real k = r / wsqrt<T>(nrm.x * nrm.x + nrm.y * nrm.y);
  px = {-(k * nrm.x), -(k * nrm.y), zr};
  const V3 v = sub(px, q);
  const real s = dot(v, nrm);
  const V3 e = sub(v, scale(s, nrm));
  py = add(q, e);
  ok &= (s > zero) & (norm2(e) <= ry * ry);
}

/// A cone's slant (X's frame: apex (0, 0, hx), base rim of radius r at -hx) against the line p + z d (d unit),
/// |z| <= hs: the generator whose tangent plane is parallel to the line (normal (2 hx C, 2 hx S, r) for the
/// generator at angle (C, S): <d, normal> = 0 has two roots; the one whose plane lies farther from the line
/// separates), then the closest points of the line and that generator, both interior (wide_gjk_box_round.inl's
/// edge-vs-slant candidate, the same closed form). px on the slant, `along` the line's parameter.
AI static void slant_line(real r, real hx, const V3& p, const V3& d, real hs, V3& px, real& along, mask& ok) {
  const real zero = splat(T(0)), one = splat(T(1));
  const real kr = T(2) * hx;
  const real a2 = d.x * d.x + d.y * d.y;
  const real kap = -(r * d.z) / kr;
  const real disc = a2 - kap * kap;
  const real root = wsqrt<T>(select(disc > zero, disc, zero));
  const real Cp = (kap * d.x - root * d.y) / a2, Sp = (kap * d.y + root * d.x) / a2;
  const real Cm = (kap * d.x + root * d.y) / a2, Sm = (kap * d.y - root * d.x) / a2;
  const real zo = p.z - hx;
  const real gp = kr * (Cp * p.x + Sp * p.y) + r * zo, gm = kr * (Cm * p.x + Sm * p.y) + r * zo;
  const mask plus = gp >= gm;
  const real C = select(plus, Cp, Cm), S = select(plus, Sp, Sm), g = select(plus, gp, gm);
  const V3 gd = {r * C, r * S, -kr}, w0 = {p.x, p.y, zo};
  const real aa = dot(d, d), bq = dot(d, gd), cq = dot(gd, gd), dd = dot(d, w0), ee = dot(gd, w0);
  const real denom = aa * cq - bq * bq;
  along = (bq * ee - cq * dd) / denom;
  const real tau = (aa * ee - bq * dd) / denom;
  ok &= (disc > zero) & (g > zero) & (tau >= zero) & (tau <= one) & (along >= -hs) & (along <= hs);
  px = {tau * gd.x, tau * gd.y, hx + tau * gd.z};
}

/// A cylinder's side (radius rc, its axis the segment p + z d, |z| <= hc, in the cone's frame) against a cone's
/// slant (radius r, half-height hx, own frame): the cylinder is the capsule of its axis segment and radius rc where
/// the closest point of the axis is interior (wide_gjk.inl's side_start()), so the slant's point px nearest to the
/// axis line (slant_line()) and the side's point py = q + rc (px - q) / |px - q| (q the axis point) are the pair's
/// closest points; ok where slant_line()'s are interior and px lies beyond the side.
AI static void side_slant(real rc, real hc, real r, real hx, const V3& p, const V3& d, V3& px, V3& py, mask& ok) {
  real along;
  slant_line(r, hx, p, d, hc, px, along, ok);
  const V3 q = add(p, scale(along, d));
  const V3 u = sub(px, q);
  const real un = norm(u);
  ok &= un > rc;
  py = add(q, scale(rc / un, u));
}

/// Cone X (own frame: radius r, half-height hx) against cone Y (centre c, unit axis b, radius ry, half-height hy)
/// slant to slant, in closed form. A slant's outward normal is constant along a generator and makes a fixed angle
/// with the axis: X's normals n have <n, e_z> = ax = r / sqrt((2 hx)^2 + r^2), Y's outward normal -n has <-n, b> =
/// ay = ry / sqrt((2 hy)^2 + ry^2). So the common normal is one of the (at most) two unit n on both circles: n = x
/// e_z + y b + z (e_z x b) with x + y beta = ax, x beta + y = -ay (beta = <e_z, b>) and z^2 (1 - beta^2) = 1 - x ax
/// + y ay (|n| = 1). Along n the pair's gap is <apex_Y - apex_X, n> (each apex lies on the generator touching the
/// plane), whose z term is z <c, e_z x b>: the root of that sign separates more, the other one cannot be the
/// optimum. The generators X's apex + tau (r n_xy / |n_xy|, -2 hx) and Y's apex + sigma (-ry u - 2 hy b) (u: n's
/// unit component orthogonal to b) lie in the two planes orthogonal to n, so their lines' closest points px, py
/// differ along n only; ok where both are interior (tau, sigma in [0, 1]) with py beyond px along n: then px, py
/// are on the slants with a common normal, the pair's closest points (KKT). Why: close cone-cone witness pairs'
/// slant-slant contacts took 8.9 mean iterations (37% of the row's after rr); GJK's supports there alternate
/// between a generator's apex and base rim point.
AI static void slant_slant(real r, real hx, const V3& c, const V3& b, real ry, real hy, V3& px, V3& py, mask& ok) {
  const real zero = splat(T(0)), one = splat(T(1));
  const real kx = T(2) * hx, ky = T(2) * hy;
  const real ax = r / wsqrt<T>(kx * kx + r * r), ay = ry / wsqrt<T>(ky * ky + ry * ry);
  const real beta = b.z, s2 = one - beta * beta;
  const real x = (ax + ay * beta) / s2, y = -(ay + ax * beta) / s2;
  const real z2 = ((one - x * ax) + y * ay) / s2;
  const real cab = c.y * b.x - c.x * b.y;  // <c, e_z x b>, e_z x b = (-b.y, b.x, 0)
  const real zm = wsqrt<T>(select(z2 > zero, z2, zero));
  const real z = select(cab < zero, -zm, zm);
  const V3 n = {y * b.x - z * b.y, y * b.y + z * b.x, x + y * b.z};
  const real kn = r / wsqrt<T>(n.x * n.x + n.y * n.y);
  const V3 d1 = {kn * n.x, kn * n.y, -kx};
  const V3 e = add(n, scale(ay, b));
  const real ke = ry / norm(e);
  const V3 d2 = sub(scale(-ke, e), scale(ky, b));
  const V3 ox = {zero, zero, hx}, oy = add(c, scale(hy, b));
  const V3 w0 = sub(ox, oy);
  const real aa = dot(d1, d1), bq = dot(d1, d2), cq = dot(d2, d2), dd = dot(d1, w0), ee = dot(d2, w0);
  const real denom = aa * cq - bq * bq;
  const real tau = (bq * ee - cq * dd) / denom, sig = (aa * ee - bq * dd) / denom;
  px = add(ox, scale(tau, d1));
  py = add(oy, scale(sig, d2));
  ok &= (s2 > zero) & (z2 > zero) & (tau >= zero) & (tau <= one) & (sig >= zero) & (sig <= one) &
        (dot(sub(py, px), n) > zero);
}

/// Cylinder / cone X (own frame: radius r, half-height hx, `xcone`) against cylinder / cone Y (centre c, unit axis
/// b, radius ry, half-height hy, `ycone`): X's facing rim (a cylinder's at sign(q.z) hx, a cone's base) against
/// Y's facing rim (centre q: a cylinder's on the side of X's centre, a cone's base; `rims`: only once per pair,
/// the problem is symmetric), X's rim deepest toward Y's facing cap disc against that disc, and X's apex (a cone)
/// against solid Y. keep(ok, px, py) takes each (px on X, py on Y, X's frame).
template <class Keep>
AI static void round_round(real r, real hx, bool xcone, const V3& c, const V3& b, real ry, real hy, bool ycone,
                           bool rims, const Keep& keep) {
  const real zero = splat(T(0));
  const mask all = splat_mask(-1);
  const real cb = dot(c, b);
  // Y's facing end: its cap (a cone: the base) on the side of X's centre (the origin), normal sy b, centre q; X's
  // facing rim: a cylinder's on the side of q.
  const real sy = ycone ? splat(T(-1)) : select(cb > zero, splat(T(-1)), splat(T(1)));
  const real zy = sy * hy;
  const V3 q = add(c, scale(zy, b)), nrm = scale(sy, b);
  const real zr = xcone ? -hx : select(q.z < zero, -hx, hx);
  if (rims) {
    V3 px, py;
    mask ok = all;
    rim_rim(r, zr, q, b, ry, px, py, ok);
    keep(ok, px, py);
  }
  {  // X's rim deepest toward Y's cap plane: a cylinder's rim on the side facing away from nrm's z
    const real zd = xcone ? -hx : select(nrm.z < zero, hx, -hx);
    V3 px, py;
    mask ok = all;
    rim_disk(r, zd, q, nrm, ry, px, py, ok);
    keep(ok, px, py);
  }
  if (xcone) {
    const V3 apex = {zero, zero, hx};
    keep(all, apex, solid_point(apex, c, b, ry, hy, ycone));
  }
}

/// Cylinder / cone X (own frame: radius r, half-height hx, `cone`) against a capsule's segment (centre p, unit
/// direction d, half-length hs, in X's frame): the segment's ends against solid X (solid_point()), X's rim facing
/// the segment's centre (a cone: its base) against the segment's line (edge_rim(): the rim angle from samples,
/// then Newton), and a cone's slant against the line (slant_line()) and its apex against the segment (the apex's
/// projection, clamped). keep(ok, px, z) takes each: px on X (X's frame), the segment's point at parameter z.
template <class Keep>
AI static void round_segment(real r, real hx, bool cone, const V3& p, const V3& d, real hs, const Keep& keep) {
  const real zero = splat(T(0)), one = splat(T(1));
  const mask all = splat_mask(-1);
  const V3 o = {zero, zero, zero}, ez = {zero, zero, one};
  for (int sg = 1; sg >= -1; sg -= 2) {
    const real z = T(sg) * hs;
    keep(all, solid_point(add(p, scale(z, d)), o, ez, r, hx, cone), z);
  }
  {
    const real zr = cone ? -hx : select(p.z < zero, -hx, hx);
    V3 px;
    real along;
    mask ok = all;
    edge_rim(r, zr, p, d, hs, px, along, ok);
    keep(ok, px, along);
  }
  if (cone) {
    V3 px;
    real along;
    mask ok = all;
    slant_line(r, hx, p, d, hs, px, along, ok);
    keep(ok, px, along);
    const real za = dot(sub(V3{zero, zero, hx}, p), d);
    keep(all, V3{zero, zero, hx}, select(za > hs, hs, select(za < -hs, -hs, za)));
  }
}

/// Where the direction n = pb - pa (A's frame) separates the cores: max over A of <x, n> below min over B of <y,
/// n>, with each core's support value in closed form (a cylinder: h |<axis, n>| + r sqrt(|n|^2 - <axis, n>^2); a
/// cone: max(h <axis, n>, -h <axis, n> + r sqrt(..)); a capsule's segment: h |<axis, n>|). Overlapping pairs keep
/// their first support point: a start near the origin slows their proof of overlap and EPA's start
/// (wide_gjk_box_round.inl's same test; box-ellipsoid's overlap penetration took 20.2 -> 37.1 iterations without).
AI static mask round_apart(ShapeType ta, ShapeType tb, const real* R, const real* t, real a0, real a1, real b0,
                           real b1, const V3& pa, const V3& pb) {
  const real zero = splat(T(0));
  const V3 n = sub(pb, pa);
  const auto ext = [&](ShapeType ty, real r, real h, real an, real n2) {
    const real ha = h * an;
    const real hab = select(ha < zero, -ha, ha);
    if (ty == ShapeType::capsule) return hab;
    const real t2 = n2 - an * an;
    const real sq = r * wsqrt<T>(select(t2 > zero, t2, zero));
    if (ty == ShapeType::cone) return select(ha > sq - ha, ha, sq - ha);
    return hab + sq;
  };
  const real n2 = norm2(n);
  const real ea = ext(ta, a0, a1, n.z, n2);
  // B's: its support value along -n about its centre, axis b: a cone's apex gives -h <b, n>, its base rim h <b, n>
  // + r sqrt(..), i.e. ext() of -<b, n>.
  const real bn = (R[2] * n.x + R[5] * n.y) + R[8] * n.z;
  const real eb = ext(tb, b0, b1, -bn, n2);
  const real tn = (t[0] * n.x + t[1] * n.y) + t[2] * n.z;
  return (tn - eb) - ea > zero;
}
