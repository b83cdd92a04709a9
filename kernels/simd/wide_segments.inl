// Sphere and capsule pairs, W pairs per register, straight from their world poses (no relative frame, no GJK
// setup): both cores are segments (a sphere's has zero length), so the answer is the closest points of two
// segments (clamped parametric solution of the 2x2 normal equations: Ericson, "Real-Time Collision Detection",
// 2005, section 5.1.9) minus the radii. The scalar version's branches (kernels/closed_forms.hpp) become lane
// selects; the arithmetic is double whatever the requested precision (as cheap here, and at least as accurate).
// Lanes this kernel does not answer -- invalid input, or cores that touch (the closest points give no normal) --
// go back to the caller, which runs the scalar path on them.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_pairs.inl.

struct WideSegments : PairLanes {
  static real clamp01(real v) { return wmin(wmax(v, splat(0.0)), splat(1.0)); }
  /// a / b where b != 0, else 0 (the lanes where b == 0 take another branch; this keeps them free of inf/NaN).
  static real divide_or_zero(real a, real b) {
    const mask nonzero = b != splat(0.0);
    return select(nonzero, a / select(nonzero, b, splat(1.0)), splat(0.0));
  }

  static real max_abs(const V3& v) { return wmax(wmax(abs(v.x), abs(v.y)), abs(v.z)); }

  /// One side's world segment [p0, p1] and swept radius, and whether its input is valid.
  struct Side {
    V3 p0, p1;
    real radius;
    mask valid;
  };

  template <bool Capsule, bool Consecutive>
  __attribute__((always_inline)) static Side load_side(const PairView& in, const std::uint32_t* shape_index,
                                                       const double* const t[3], const double* const q[4],
                                                       const Block& b) {
    Pose p = load_pose<Consecutive>(in, shape_index, t, q, b.idx);
    Side s;
    s.valid = p.valid;
    s.radius = field(in.shape_size[0], p) + field(in.shape_inflation, p);
    if (!Capsule) {
      s.p0 = s.p1 = p.t;
      return s;
    }
    const real half = field(in.shape_size[1], p);
    normalize(p);
    const V3 axis = column(p, 2);  // the capsule's local z axis
    s.p0 = sub(p.t, scale(half, axis));
    s.p1 = add(p.t, scale(half, axis));
    return s;
  }

  /// Closest points ca on A's segment and cb on B's (closest_points_segments in closed_forms.hpp, as selects).
  template <bool CapsuleA, bool CapsuleB>
  __attribute__((always_inline)) static void closest_points(const Side& A, const Side& B, V3& ca, V3& cb) {
    if (!CapsuleA && !CapsuleB) {
      ca = A.p0, cb = B.p0;
      return;
    }
    const V3 d1 = sub(A.p1, A.p0), d2 = sub(B.p1, B.p0), r = sub(A.p0, B.p0);
    const real zero = splat(0.0), one = splat(1.0);
    real s = zero, t = zero;
    if (!CapsuleA) {
      t = clamp01(divide_or_zero(dot(d2, r), dot(d2, d2)));
    } else if (!CapsuleB) {
      s = clamp01(divide_or_zero(-dot(d1, r), dot(d1, d1)));
    } else {
      const real a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
      const mask a_zero = a == zero, e_zero = e == zero;
      const real denom = a * e - b * b;  // >= 0; zero for parallel segments, where any s works: take s = 0
      const real s_free = select(denom > zero, clamp01(divide_or_zero(b * f - c * e, denom)), zero);
      const real t_free = divide_or_zero(b * s_free + f, e);
      const mask below = t_free < zero, above = t_free > one;
      s = select(below, clamp01(divide_or_zero(-c, a)), select(above, clamp01(divide_or_zero(b - c, a)), s_free));
      t = select(below, zero, select(above, one, t_free));
      // Degenerate segments (zero length), as in the scalar version's first branches.
      s = select(e_zero, clamp01(divide_or_zero(-c, a)), s);
      t = select(e_zero, zero, t);
      s = select(a_zero, zero, s);
      t = select(a_zero, select(e_zero, zero, clamp01(divide_or_zero(f, e))), t);
    }
    ca = add(A.p0, scale(s, d1));
    cb = add(B.p0, scale(t, d2));
  }

  /// Answers pairs[0 .. n) (all of types A-B, each a sphere or a capsule); indices of the pairs it leaves to the
  /// scalar path go to fallback[0 .. returned count).
  template <bool CapsuleA, bool CapsuleB>
  static std::size_t run(const PairView& in_arg, const std::uint32_t* pairs, std::size_t n,
                         const ClosedFormQuery& query, const ResultView& out_arg, std::uint32_t* fallback) {
    // Local copies: the collide and status stores are bytes, which may alias anything, so with the caller's
    // structs the compiler would reload every array pointer after them.
    const PairView in = in_arg;
    const ResultView out = out_arg;
    std::size_t fallbacks = 0;
    if (in.shape_count == 0) {
      for (std::size_t k = 0; k < n; ++k) fallback[fallbacks++] = pairs[k];
      return fallbacks;
    }
    for (std::size_t k = 0; k < n; k += W) {
      const Block b = block(pairs, n, k);
      if (b.consecutive) answer<CapsuleA, CapsuleB, true>(in, b, query, out, fallback, fallbacks);
      else answer<CapsuleA, CapsuleB, false>(in, b, query, out, fallback, fallbacks);
    }
    return fallbacks;
  }

  /// One block of W pairs.
  template <bool CapsuleA, bool CapsuleB, bool Consecutive>
  __attribute__((always_inline)) static void answer(const PairView& in, const Block& b, const ClosedFormQuery& query,
                                                    const ResultView& out, std::uint32_t* fallback,
                                                    std::size_t& fallbacks) {
    const Side A = load_side<CapsuleA, Consecutive>(in, in.shape_a, in.translation_a, in.rotation_a, b);
    const Side B = load_side<CapsuleB, Consecutive>(in, in.shape_b, in.translation_b, in.rotation_b, b);
    V3 ca, cb;
    closest_points<CapsuleA, CapsuleB>(A, B, ca, cb);
    const V3 v = sub(cb, ca);
    const real core = wsqrt<double>(dot(v, v));
    const real signed_distance = (core - A.radius) - B.radius;
    // Touching cores (the scalar rule in segments_with_radii: within kSegmentTouchUlps of the coordinates)
    // need the scalar path's normal.
    const real coordinates = wmax(wmax(max_abs(A.p0), max_abs(A.p1)), wmax(max_abs(B.p0), max_abs(B.p1)));
    const real touch = splat(kSegmentTouchUlps * std::numeric_limits<double>::epsilon()) * coordinates;
    const mask answered = A.valid & B.valid & (core > touch);
    const std::uint32_t mine = lane_bits(answered) & b.live;
    const bool whole = write_collide(b, mine, signed_distance <= splat(query.margin), out, fallback, fallbacks);
    const bool has_distance = query.level >= QueryLevel::distance, has_points = query.level >= QueryLevel::witness;
    write_defaults(b, whole, mine, out);
    if (has_distance) store(out.distance, b.idx, whole, signed_distance, mine);
    if (has_points) {
      const real safe_core = select(answered, core, splat(1.0));
      const V3 normal{v.x / safe_core, v.y / safe_core, v.z / safe_core};
      const V3 wa = add(ca, scale(A.radius, normal)), wb = sub(cb, scale(B.radius, normal));
      const V3* vecs[3] = {&wa, &wb, &normal};
      double* const* dst[3] = {out.witness_a, out.witness_b, out.normal};
      for (int j = 0; j < 3; ++j) {
        store(dst[j][0], b.idx, whole, vecs[j]->x, mine);
        store(dst[j][1], b.idx, whole, vecs[j]->y, mine);
        store(dst[j][2], b.idx, whole, vecs[j]->z, mine);
      }
    }
  }
};
