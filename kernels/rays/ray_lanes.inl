// The body of the lane kernels (see ray_lanes.hpp), included once per instruction set inside a `#pragma GCC target`
// region and a namespace that defines: W; VD / VF (W lanes of double / float, or the scalars when W = 1);
// loadd(const double*), stored(double*, VD), to_float(VD), to_double(VF), lsqrt(VD), lsqrt(VF), float_up(VD)
// (smallest floats >= the lanes, which are >= 0), mnot / mand / mor on masks, all_true(mask), store_hits(hit, status,
// mask) and lane_index(i, l) helpers. Every operation below is lane-wise IEEE arithmetic, the same for any W.

namespace {

template <class T> using LV = std::conditional_t<std::is_same_v<T, double>, VD, VF>;

template <class T> inline LV<T> from_d(VD x) {
  if constexpr (std::is_same_v<T, double>) return x;
  else return to_float(x);
}

template <class V> inline V splat(double x) {
  if constexpr (std::is_arithmetic_v<V>) {
    return V(x);
  } else {
    using S = std::remove_cv_t<std::remove_reference_t<decltype(std::declval<V>()[0])>>;
    return V{} + S(x);
  }
}

template <class M, class V> inline V sel(M m, V a, V b) { return m ? a : b; }

template <class V> struct Interval {
  V enter, exit, nx, ny, nz;  // normal at enter
};

template <class V> inline auto is_empty(const Interval<V>& in) { return mnot(in.enter <= in.exit); }

// The ball of radius r about the origin; a = |d|^2 > 0. Closest-point form (see ray_quadrics.hpp).
template <class V> Interval<V> ball(V ox, V oy, V oz, V dx, V dy, V dz, V a, V r) {
  const V inf = splat<V>(INFINITY), zero = splat<V>(0.0);
  const V tc = -((ox * dx + oy * dy) + oz * dz) / a;
  const V px = ox + tc * dx, py = oy + tc * dy, pz = oz + tc * dz;
  const V h2 = r * r - ((px * px + py * py) + pz * pz);
  const auto ok = h2 >= zero;  // false for NaN
  const V half = lsqrt(sel(ok, h2, zero) / a);
  Interval<V> in;
  in.enter = sel(ok, tc - half, inf);
  in.exit = sel(ok, tc + half, -inf);
  const V inv_r = splat<V>(1.0) / r;
  in.nx = (ox + in.enter * dx) * inv_r, in.ny = (oy + in.enter * dy) * inv_r, in.nz = (oz + in.enter * dz) * inv_r;
  return in;
}

// The slab lo <= o + t d <= hi (lo = -e, hi = e) along one axis; normal component -1 / +1 on that axis.
template <class V> void slab(V o, V d, V e, V& enter, V& exit, V& n) {
  const V inf = splat<V>(INFINITY), zero = splat<V>(0.0), one = splat<V>(1.0);
  const auto flat = d == zero, pos = d > zero;
  const V inv = one / sel(flat, one, d);  // one division per axis: t within 1.5 ulps instead of 0.5
  const V t_lo = (-e - o) * inv, t_hi = (e - o) * inv;
  const auto inside = mand(o >= -e, o <= e);
  enter = sel(flat, sel(inside, -inf, inf), sel(pos, t_lo, t_hi));
  exit = sel(flat, sel(inside, inf, -inf), sel(pos, t_hi, t_lo));
  n = sel(pos, -one, one);
}

template <class V> Interval<V> intersect(const Interval<V>& a, const Interval<V>& b) {
  const auto ge = a.enter >= b.enter;
  return {sel(ge, a.enter, b.enter), sel(a.exit <= b.exit, a.exit, b.exit), sel(ge, a.nx, b.nx), sel(ge, a.ny, b.ny),
          sel(ge, a.nz, b.nz)};
}

template <class V> Interval<V> unite(const Interval<V>& a, const Interval<V>& b) {
  const auto le = a.enter <= b.enter;
  const Interval<V> u{sel(le, a.enter, b.enter), sel(a.exit >= b.exit, a.exit, b.exit), sel(le, a.nx, b.nx),
                      sel(le, a.ny, b.ny), sel(le, a.nz, b.nz)};
  const auto a_empty = is_empty(a), b_empty = is_empty(b);
  const auto pick = [&](V ua, V va, V vb) { return sel(b_empty, va, sel(a_empty, vb, ua)); };
  return {pick(u.enter, a.enter, b.enter), pick(u.exit, a.exit, b.exit), pick(u.nx, a.nx, b.nx),
          pick(u.ny, a.ny, b.ny), pick(u.nz, a.nz, b.nz)};
}

template <class V> Interval<V> box(V ox, V oy, V oz, V dx, V dy, V dz, V ex, V ey, V ez) {
  const V zero = splat<V>(0.0);
  Interval<V> x, y, z;
  V n;
  slab(ox, dx, ex, x.enter, x.exit, n);
  x.nx = n, x.ny = zero, x.nz = zero;
  slab(oy, dy, ey, y.enter, y.exit, n);
  y.nx = zero, y.ny = n, y.nz = zero;
  slab(oz, dz, ez, z.enter, z.exit, n);
  z.nx = zero, z.ny = zero, z.nz = n;
  return intersect(intersect(x, y), z);
}

// Capsule: segment z in [-h, h] swept by r: the union of the end balls and the body (infinite cylinder within the
// z slab); the balls win ties (ray_quadrics.hpp).
template <class V> Interval<V> capsule(V ox, V oy, V oz, V dx, V dy, V dz, V a, V r, V h) {
  const V inf = splat<V>(INFINITY), zero = splat<V>(0.0), one = splat<V>(1.0);
  Interval<V> cyl;
  const V ar = dx * dx + dy * dy;
  const auto parallel = ar == zero;
  const V as = sel(parallel, one, ar);
  const V tc = -(ox * dx + oy * dy) / as;
  const V px = ox + tc * dx, py = oy + tc * dy;
  const V h2 = r * r - (px * px + py * py);
  const auto ok = h2 >= zero;
  const V half = lsqrt(sel(ok, h2, zero) / as);
  const auto axis_inside = ox * ox + oy * oy <= r * r;
  cyl.enter = sel(parallel, sel(axis_inside, -inf, inf), sel(ok, tc - half, inf));
  cyl.exit = sel(parallel, sel(axis_inside, inf, -inf), sel(ok, tc + half, -inf));
  const V inv_r = one / r;
  cyl.nx = (ox + cyl.enter * dx) * inv_r, cyl.ny = (oy + cyl.enter * dy) * inv_r, cyl.nz = zero;
  Interval<V> ends;
  V n;
  slab(oz, dz, h, ends.enter, ends.exit, n);
  ends.nx = zero, ends.ny = zero, ends.nz = n;
  const Interval<V> body = intersect(cyl, ends);
  const Interval<V> top = ball(ox, oy, oz - h, dx, dy, dz, a, r), bottom = ball(ox, oy, oz + h, dx, dy, dz, a, r);
  return unite(unite(top, bottom), body);
}

template <class T> bool cast(const LaneShapeTable& shapes, const LaneRays& r, std::size_t i, LaneOut& out) {
  using V = LV<T>;
  // Shapes: one lane kind for all W rays.
  const std::size_t count = shapes.kind.size();
  LaneKind kind = LaneKind::none;
  double sa[W], sb[W], sc[W];
  const HullPlanes<T>* hull[W];
  for (int l = 0; l < W; ++l) {
    const std::uint32_t s = r.shape[i + l];
    if (s >= count) return false;
    const LaneKind k = shapes.kind[s];
    if (k == LaneKind::none || (l > 0 && k != kind)) return false;
    kind = k, sa[l] = shapes.a[s], sb[l] = shapes.b[s], sc[l] = shapes.c[s];
    if constexpr (std::is_same_v<T, double>) hull[l] = k == LaneKind::hull ? shapes.hull_d[s] : nullptr;
    else hull[l] = k == LaneKind::hull ? shapes.hull_f[s] : nullptr;
    if (k == LaneKind::hull && hull[l] == nullptr) return false;
  }
  // Validity (batchcol/rays.hpp), in double as the general path checks it.
  const VD ox = loadd(r.ox + i), oy = loadd(r.oy + i), oz = loadd(r.oz + i);
  const VD dx = loadd(r.dx + i), dy = loadd(r.dy + i), dz = loadd(r.dz + i), tm = loadd(r.t_max + i);
  const VD px = loadd(r.px + i), py = loadd(r.py + i), pz = loadd(r.pz + i);
  const VD qw = loadd(r.qw + i), qx = loadd(r.qx + i), qy = loadd(r.qy + i), qz = loadd(r.qz + i);
  const VD zd = splat<VD>(0.0);
  const auto finite = [&](VD x) { return (x - x) == zd; };
  const VD qn = lsqrt(((qw * qw + qx * qx) + qy * qy) + qz * qz);
  const VD dev = qn - splat<VD>(1.0);
  auto valid = mand(mand(mand(finite(ox), finite(oy)), mand(finite(oz), finite(dx))), mand(finite(dy), finite(dz)));
  valid = mand(valid, mand(((dx * dx + dy * dy) + dz * dz) > zd, tm >= zd));
  valid = mand(valid, mand(mand(finite(px), finite(py)), finite(pz)));
  valid = mand(valid, mand(dev <= splat<VD>(0.5e-6), dev >= splat<VD>(-0.5e-6)));  // kUnitTolerance / 2
  if (!all_true(valid)) return false;

  // The ray relative to the shape's centre, in T (the difference in double first, as the general path does).
  const V cx = from_d<T>(ox - px), cy = from_d<T>(oy - py), cz = from_d<T>(oz - pz);
  const V wx = from_d<T>(dx), wy = from_d<T>(dy), wz = from_d<T>(dz);
  V t_max;
  if constexpr (std::is_same_v<T, double>) t_max = tm;
  else t_max = float_up(tm);  // rounded up: no hit inside the requested range is lost
  VD ad, bd, cd;
  for (int l = 0; l < W; ++l) lane_set(ad, l, sa[l]), lane_set(bd, l, sb[l]), lane_set(cd, l, sc[l]);
  const V A = from_d<T>(ad), B = from_d<T>(bd), C = from_d<T>(cd);
  const V a = (wx * wx + wy * wy) + wz * wz;

  Interval<V> in;
  V m[9];  // rotation, column-major (kernels::rotation_matrix's entries)
  if (kind == LaneKind::sphere) {
    in = ball(cx, cy, cz, wx, wy, wz, a, A);  // rotation-invariant: world frame about the centre
  } else {
    const VD inv_qn = splat<VD>(1.0) / qn;
    const V w = from_d<T>(qw * inv_qn), x = from_d<T>(qx * inv_qn), y = from_d<T>(qy * inv_qn),
            z = from_d<T>(qz * inv_qn);
    const V one = splat<V>(1.0), two = splat<V>(2.0);
    m[0] = one - two * (y * y + z * z), m[1] = two * (x * y + w * z), m[2] = two * (x * z - w * y);
    m[3] = two * (x * y - w * z), m[4] = one - two * (x * x + z * z), m[5] = two * (y * z + w * x);
    m[6] = two * (x * z + w * y), m[7] = two * (y * z - w * x), m[8] = one - two * (x * x + y * y);
    // Local frame: R^T (x - p).
    const V lox = (m[0] * cx + m[1] * cy) + m[2] * cz, loy = (m[3] * cx + m[4] * cy) + m[5] * cz,
            loz = (m[6] * cx + m[7] * cy) + m[8] * cz;
    const V ldx = (m[0] * wx + m[1] * wy) + m[2] * wz, ldy = (m[3] * wx + m[4] * wy) + m[5] * wz,
            ldz = (m[6] * wx + m[7] * wy) + m[8] * wz;
    if (kind == LaneKind::box) {
      in = box(lox, loy, loz, ldx, ldy, ldz, A, B, C);
    } else if (kind == LaneKind::capsule) {
      const V la = (ldx * ldx + ldy * ldy) + ldz * ldz;
      in = capsule(lox, loy, loz, ldx, ldy, ldz, la, A, B);
    } else {
      // Hulls: the bounding ball (inflated by 64 ulps, as ray_local's) on whole registers, then lane by lane the
      // scalar walk from the ball's entry; a hit becomes the interval [t, inf) (t = 0 from inside).
      const V grow = splat<V>(double(T(1) + T(64) * machine_epsilon<T>()));
      const V la = (ldx * ldx + ldy * ldy) + ldz * ldz;
      const Interval<V> bl = ball(lox, loy, loz, ldx, ldy, ldz, la, A * grow);
      in.enter = splat<V>(INFINITY);
      in.exit = -in.enter;  // empty unless the lane hits
      in.nx = in.ny = in.nz = splat<V>(0.0);
      for (int l = 0; l < W; ++l) {
        const T ball_enter = lane_get(bl.enter, l), ball_exit = lane_get(bl.exit, l), tm_l = lane_get(t_max, l);
        if (!(ball_enter <= ball_exit) || ball_exit < T(0) || ball_enter > tm_l) continue;
        const T o[3] = {lane_get(lox, l), lane_get(loy, l), lane_get(loz, l)};
        const T d[3] = {lane_get(ldx, l), lane_get(ldy, l), lane_get(ldz, l)};
        T enter, nl[3];
        hull_lane<T>(*hull[l], sa[l], o, d, tm_l, ball_enter, enter, nl, kLaneIsa);
        lane_set(in.enter, l, enter);
        if (enter < infinity<T>()) {
          lane_set(in.exit, l, infinity<T>());
          lane_set(in.nx, l, nl[0]), lane_set(in.ny, l, nl[1]), lane_set(in.nz, l, nl[2]);
        }
      }
    }
    // Back to the world frame: R n.
    const V nx = (m[0] * in.nx + m[3] * in.ny) + m[6] * in.nz, ny = (m[1] * in.nx + m[4] * in.ny) + m[7] * in.nz,
            nz = (m[2] * in.nx + m[5] * in.ny) + m[8] * in.nz;
    in.nx = nx, in.ny = ny, in.nz = nz;
  }
  // finish(): the segment [0, t_max]; a ray starting inside hits at 0 with normal -d / |d|.
  const V zero = splat<V>(0.0), nan = splat<V>(NAN);
  const auto hit = mand(mnot(is_empty(in)), mand(mnot(in.exit < zero), mnot(in.enter > t_max)));
  const auto inside = in.enter <= zero;
  const V inv_len = splat<V>(-1.0) / lsqrt(a);
  const V t = sel(hit, sel(inside, zero, in.enter), nan);
  const V nx = sel(hit, sel(inside, wx * inv_len, in.nx), nan), ny = sel(hit, sel(inside, wy * inv_len, in.ny), nan),
          nz = sel(hit, sel(inside, wz * inv_len, in.nz), nan);
  if constexpr (std::is_same_v<T, double>) {
    stored(out.t + i, t), stored(out.nx + i, nx), stored(out.ny + i, ny), stored(out.nz + i, nz);
  } else {
    stored(out.t + i, to_double(t)), stored(out.nx + i, to_double(nx)), stored(out.ny + i, to_double(ny));
    stored(out.nz + i, to_double(nz));
  }
  store_hits(out.hit + i, out.status + i, hit);
  return true;
}

}  // namespace

bool cast_double(const LaneShapeTable& s, const LaneRays& r, std::size_t i, LaneOut& o) { return cast<double>(s, r, i, o); }
bool cast_float(const LaneShapeTable& s, const LaneRays& r, std::size_t i, LaneOut& o) { return cast<float>(s, r, i, o); }
