// Sphere against a cylinder, a cone or a box, W pairs per register, straight from the world poses: the sphere's core
// is a point, so the answer is the point's distance to the solid. For a solid of revolution that is a 2D problem in
// the solid's (rho, z) half-plane (rho = distance to the axis), where the cylinder is a rectangle and the cone a
// triangle; for a box, the point clamped to the box (kernels/closed_forms.hpp's sphere_box(), which the per-pair path
// runs one pair at a time at ~1200 instructions). Exact to rounding, where GJK would iterate to a tolerance (2
// iterations on separated pairs, EPA on overlapping ones). The arithmetic is double whatever the requested precision
// (as the segment closed forms).
//   Outside: the closest point of the boundary (the cap / base, the side / slant edge; the clamped point), clamped.
//   Inside: the nearer of those boundary pieces (depth = its distance), the normal its outward normal.
// Lanes this kernel does not answer -- invalid input, or a point on the boundary to rounding (no normal: the
// scalar path's GJK / EPA decides) -- go back to the caller.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_pairs.inl.

struct WidePointSolids : PairLanes {
  /// Touching: a point within this many ulps of the section's coordinates from the boundary has no reliable
  /// normal (its direction is rounding); those pairs take the scalar path, as touching segment cores do.
  static constexpr double kTouchUlps = 16;

  /// The point's closest boundary point of the section, in (rho, z), its outward normal (nr, nz) there, and the
  /// signed distance (negative inside).
  struct Section {
    real qr, qz, nr, nz, distance, scale;
  };

  /// Cylinder of radius R and half length h: the rectangle [0, R] x [-h, h].
  static Section cylinder(real rho, real z, real R, real h) {
    const real zero = splat(0.0), one = splat(1.0);
    Section s;
    const real az = abs(z);
    const real side = rho - R, cap = az - h;  // > 0: beyond the side / the cap
    const mask outside = (side > zero) | (cap > zero);
    const real cap_z = select(z < zero, -h, h);
    // Outside: the clamped point; its offset from the point gives distance and normal.
    const real cr = wmin(rho, R), cz = select(az > h, cap_z, z);
    const real dr = rho - cr, dz = z - cz;
    const real out_distance = wsqrt<double>(dr * dr + dz * dz);
    const real safe = select(out_distance > zero, out_distance, one);
    // Inside: the nearer of the side (depth R - rho) and the cap (depth h - |z|); the side on ties.
    const mask to_side = -side <= -cap;
    s.qr = select(outside, cr, select(to_side, R, rho));
    s.qz = select(outside, cz, select(to_side, z, cap_z));
    s.nr = select(outside, dr / safe, select(to_side, one, zero));
    s.nz = select(outside, dz / safe, select(to_side, zero, select(z < zero, -one, one)));
    s.distance = select(outside, out_distance, wmax(side, cap));
    s.scale = wmax(R, h);
    return s;
  }

  /// Cone of base radius R, half length h, apex at z = h: the triangle (0, -h), (R, -h), (0, h) for rho >= 0.
  static Section cone(real rho, real z, real R, real h) {
    const real zero = splat(0.0), one = splat(1.0);
    Section s;
    // The slant edge from the rim (R, -h) to the apex (0, h): direction e = (-R, 2h), outward normal (2h, R) / L.
    const real er = -R, ez = h + h, L = wsqrt<double>(ez * ez + R * R);
    const real slant = ((rho - R) * ez + (z + h) * R) / L;  // signed distance to the slant line, > 0 outside
    const real base = -(z + h);                             // signed distance to the base plane, > 0 below it
    const mask outside = (slant > zero) | (base > zero);
    // Outside: the closer of the clamped points of the base segment and of the slant segment.
    const real br = wmin(rho, R), bdr = rho - br, bdz = z + h;
    const real b2 = bdr * bdr + bdz * bdz;
    const real t = wmin(wmax(((rho - R) * er + (z + h) * ez) / (er * er + ez * ez), zero), one);
    const real sr = R + t * er, sz = -h + t * ez;
    const real sdr = rho - sr, sdz = z - sz;
    const real s2 = sdr * sdr + sdz * sdz;
    const mask via_base = b2 <= s2;
    const real cr = select(via_base, br, sr), cz = select(via_base, -h, sz);
    const real dr = rho - cr, dz = z - cz;
    const real out_distance = wsqrt<double>(select(via_base, b2, s2));
    const real safe = select(out_distance > zero, out_distance, one);
    // Inside: the nearer of the base (depth z + h) and the slant (depth -slant); the slant on ties.
    const mask to_slant = -slant <= -base;
    s.qr = select(outside, cr, select(to_slant, rho - slant * (ez / L), rho));
    s.qz = select(outside, cz, select(to_slant, z - slant * (R / L), -h));
    s.nr = select(outside, dr / safe, select(to_slant, ez / L, zero));
    s.nz = select(outside, dz / safe, select(to_slant, R / L, -one));
    s.distance = select(outside, out_distance, wmax(slant, base));
    s.scale = wmax(R, h);
    return s;
  }

  /// The point's closest boundary point of the solid, q, the outward normal there, n (the solid's frame), the
  /// signed distance and the size the touching test scales its ulps by.
  struct Local {
    V3 q, n;
    real distance, scale;
  };

  /// A section's answer in 3D: (rho, z) turned about the axis to the point's radial unit vector (ux, uy).
  static Local revolve(const Section& s, real ux, real uy, real rho, real z) {
    return {{s.qr * ux, s.qr * uy, s.qz}, {s.nr * ux, s.nr * uy, s.nz}, s.distance, wmax(s.scale, rho + abs(z))};
  }

  /// Box of half extents h: the point c clamped to it (outside), else the face of least depth, x before y before z
  /// on ties (sphere_box()'s choice).
  static Local box(const real (&c)[3], const real (&h)[3]) {
    const real zero = splat(0.0), one = splat(1.0);
    real q[3], v[3], room[3];
    mask outside = mask{};
    for (int i = 0; i < 3; ++i) {
      q[i] = wmin(wmax(c[i], zero - h[i]), h[i]);
      v[i] = c[i] - q[i];
      outside |= v[i] != zero;
      room[i] = h[i] - abs(c[i]);  // depth under the face on the point's side
    }
    const real out_distance = wsqrt<double>(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const real safe = select(out_distance > zero, out_distance, one);
    const mask to_y = room[1] < room[0];
    const mask to_z = room[2] < select(to_y, room[1], room[0]);
    const mask axis[3] = {~(to_y | to_z), to_y & ~to_z, to_z};
    Local l;
    real* const lq[3] = {&l.q.x, &l.q.y, &l.q.z};
    real* const ln[3] = {&l.n.x, &l.n.y, &l.n.z};
    real depth = room[0];
    for (int i = 0; i < 3; ++i) {
      const real sgn = select(c[i] < zero, -one, one);
      *lq[i] = select(outside, q[i], select(axis[i], sgn * h[i], c[i]));
      *ln[i] = select(outside, v[i] / safe, select(axis[i], sgn, zero));
      depth = select(axis[i], room[i], depth);
    }
    l.distance = select(outside, out_distance, zero - depth);
    l.scale = wmax(wmax(wmax(h[0], h[1]), h[2]), (abs(c[0]) + abs(c[1])) + abs(c[2]));
    return l;
  }

  /// Answers pairs[0 .. n) (A of the sphere type when `sphere_a`, the other side a PointSolid: cylinder, cone or
  /// box); indices of the pairs it leaves to the scalar path go to fallback[0 .. returned count).
  template <bool SphereA, PointSolid Solid>
  static std::size_t run(const PairView& in_arg, const std::uint32_t* pairs, std::size_t n,
                         const ClosedFormQuery& query, const ResultView& out_arg, std::uint32_t* fallback) {
    const PairView in = in_arg;  // local copies: byte stores may alias anything (see WideSegments::run)
    const ResultView out = out_arg;
    std::size_t fallbacks = 0;
    if (in.shape_count == 0) {
      for (std::size_t k = 0; k < n; ++k) fallback[fallbacks++] = pairs[k];
      return fallbacks;
    }
    for (std::size_t k = 0; k < n; k += W) {
      const Block b = block(pairs, n, k);
      if (b.consecutive) answer<SphereA, Solid, true>(in, b, query, out, fallback, fallbacks);
      else answer<SphereA, Solid, false>(in, b, query, out, fallback, fallbacks);
    }
    return fallbacks;
  }

  template <bool SphereA, PointSolid Solid, bool Consecutive>
  __attribute__((always_inline)) static void answer(const PairView& in, const Block& b, const ClosedFormQuery& query,
                                                    const ResultView& out, std::uint32_t* fallback,
                                                    std::size_t& fallbacks) {
    Pose ps = load_pose<Consecutive>(in, SphereA ? in.shape_a : in.shape_b, SphereA ? in.translation_a : in.translation_b,
                                     SphereA ? in.rotation_a : in.rotation_b, b.idx);
    Pose pc = load_pose<Consecutive>(in, SphereA ? in.shape_b : in.shape_a, SphereA ? in.translation_b : in.translation_a,
                                     SphereA ? in.rotation_b : in.rotation_a, b.idx);
    const real sphere_radius = field(in.shape_size[0], ps) + field(in.shape_inflation, ps);
    const real inflation = field(in.shape_inflation, pc);
    normalize(pc);
    const V3 axis[3] = {column(pc, 0), column(pc, 1), column(pc, 2)};
    const V3 d = sub(ps.t, pc.t);  // the sphere's centre relative to the solid, world axes
    const real x = dot(axis[0], d), y = dot(axis[1], d), z = dot(axis[2], d);
    Local s;
    if constexpr (Solid == PointSolid::box) {
      const real h[3] = {field(in.shape_size[0], pc), field(in.shape_size[1], pc), field(in.shape_size[2], pc)};
      s = box({x, y, z}, h);
    } else {
      const real zero = splat(0.0), one = splat(1.0);
      const real R = field(in.shape_size[0], pc), h = field(in.shape_size[1], pc);
      const real rho = wsqrt<double>(x * x + y * y);
      const Section sec = Solid == PointSolid::cone ? cone(rho, z, R, h) : cylinder(rho, z, R, h);
      // The section's (rho, z) back to 3D: the radial unit vector of the point (the x axis on the axis itself).
      const mask on_axis = rho == zero;
      const real safe_rho = select(on_axis, one, rho);
      s = revolve(sec, select(on_axis, one, x / safe_rho), select(on_axis, zero, y / safe_rho), rho, z);
    }
    const real touch = splat(kTouchUlps * std::numeric_limits<double>::epsilon()) * s.scale;
    const mask answered = ps.valid & pc.valid & (abs(s.distance) > touch);
    const real signed_distance = (s.distance - sphere_radius) - inflation;
    const std::uint32_t mine = lane_bits(answered) & b.live;
    const bool whole = write_collide(b, mine, signed_distance <= splat(query.margin), out, fallback, fallbacks);
    write_defaults(b, whole, mine, out);
    if (query.level >= QueryLevel::distance) store(out.distance, b.idx, whole, signed_distance, mine);
    if (query.level < QueryLevel::witness) return;
    // World normal outward from the solid, its boundary point, and the sphere's centre.
    const V3 n_out = add(add(scale(s.n.x, axis[0]), scale(s.n.y, axis[1])), scale(s.n.z, axis[2]));
    const V3 q = add(pc.t, add(add(scale(s.q.x, axis[0]), scale(s.q.y, axis[1])), scale(s.q.z, axis[2])));
    const V3 on_solid = add(q, scale(inflation, n_out));
    const V3 on_sphere = sub(ps.t, scale(sphere_radius, n_out));
    // The normal points from A to B.
    const V3 normal = SphereA ? V3{-n_out.x, -n_out.y, -n_out.z} : n_out;
    const V3& wa = SphereA ? on_sphere : on_solid;
    const V3& wb = SphereA ? on_solid : on_sphere;
    const V3* vecs[3] = {&wa, &wb, &normal};
    double* const* dst[3] = {out.witness_a, out.witness_b, out.normal};
    for (int j = 0; j < 3; ++j) {
      store(dst[j][0], b.idx, whole, vecs[j]->x, mine);
      store(dst[j][1], b.idx, whole, vecs[j]->y, mine);
      store(dst[j][2], b.idx, whole, vecs[j]->z, mine);
    }
  }
};
