// Sphere and capsule pairs, W pairs per register, straight from their world poses (no relative frame, no GJK
// setup): both cores are segments (a sphere's has zero length), so the answer is the closest points of two
// segments (clamped parametric solution of the 2x2 normal equations: Ericson, "Real-Time Collision Detection",
// 2005, section 5.1.9) minus the radii. The scalar version's branches (kernels/closed_forms.hpp) become lane
// selects; the arithmetic is double whatever the requested precision (as cheap here, and at least as accurate).
// Lanes this kernel does not answer -- invalid input, or cores that touch (the closest points give no normal) --
// go back to the caller, which runs the scalar path on them.
//
// No include guard: included once per instruction set by isa_body.inl, after wide.hpp, inside the ISA namespace.

struct WideSegments {
  using real = wreal<double>;
  using mask = wmask<double>;
  static constexpr int W = Wide<double>::W;

  struct V3 {
    real x, y, z;
  };
  static real splat(double v) { return real{} + v; }
  static V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  static V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static V3 scale(real s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
  static real dot(const V3& a, const V3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
  static real clamp01(real v) { return wmin(wmax(v, splat(0.0)), splat(1.0)); }
  /// a / b where b != 0, else 0 (the lanes where b == 0 take another branch; this keeps them free of inf/NaN).
  static real divide_or_zero(real a, real b) {
    const mask nonzero = b != splat(0.0);
    return select(nonzero, a / select(nonzero, b, splat(1.0)), splat(0.0));
  }

  /// Lane l = a[idx[l]]: one vector load when the indices are consecutive.
  static real load(const double* a, const std::uint32_t* idx, bool consecutive) {
    real r;
    if (consecutive) {
      __builtin_memcpy(&r, a + idx[0], sizeof r);
    } else {
      for (int l = 0; l < W; ++l) r[l] = a[idx[l]];
    }
    return r;
  }
  static void store(double* a, const std::uint32_t* idx, bool consecutive, real v, std::uint32_t lanes) {
    if (consecutive) {
      __builtin_memcpy(a + idx[0], &v, sizeof v);
    } else {
      for (int l = 0; l < W; ++l)
        if ((lanes >> l) & 1u) a[idx[l]] = v[l];
    }
  }
  /// Byte offsets of the lanes' shapes in the ShapeTable (pair idx[l]'s entry of shape_index), and whether each
  /// index is in range (out-of-range lanes read shape 0 and are marked invalid).
  static mask shape_offsets(const PairView& in, const std::uint32_t* shape_index, const std::uint32_t* idx,
                            bool consecutive, mask& in_range) {
    typedef std::uint32_t lanes32 __attribute__((vector_size(sizeof(std::uint32_t) * W)));
    lanes32 raw;
    if (consecutive) {
      __builtin_memcpy(&raw, shape_index + idx[0], sizeof raw);
    } else {
      for (int l = 0; l < W; ++l) raw[l] = shape_index[idx[l]];
    }
    const mask shape = __builtin_convertvector(raw, mask);  // zero-extended: 64-bit lanes
    in_range = shape < (mask{} + typename Wide<double>::Int(in.shape_count));
    return select(in_range, shape, mask{}) * typename Wide<double>::Int(in.shape_stride);
  }

  /// One side's world segment [p0, p1] and swept radius, and whether its input is valid.
  struct Side {
    V3 p0, p1;
    real radius;
    mask valid;
  };

  template <bool Capsule>
  static Side load_side(const PairView& in, const std::uint32_t* shape_index, const double* const t[3],
                        const double* const q[4], const std::uint32_t* idx, bool consecutive) {
    Side s;
    const V3 c{load(t[0], idx, consecutive), load(t[1], idx, consecutive), load(t[2], idx, consecutive)};
    real w = load(q[0], idx, consecutive), x = load(q[1], idx, consecutive), y = load(q[2], idx, consecutive),
         z = load(q[3], idx, consecutive);
    // The executor's rule (batchcol::is_unit_quaternion): finite and | |q| - 1 | <= kUnitTolerance; NaN and
    // infinite components fail both comparisons. Then q is normalised.
    const real norm = wsqrt<double>(((w * w + x * x) + y * y) + z * z);
    const real deviation = norm - splat(1.0);
    const real zero = splat(0.0);
    s.valid = (deviation <= splat(kUnitTolerance)) & (deviation >= splat(-kUnitTolerance)) &
              (c.x - c.x == zero) & (c.y - c.y == zero) & (c.z - c.z == zero);
    mask in_range;
    const mask offset = shape_offsets(in, shape_index, idx, consecutive, in_range);
    s.valid &= in_range;
    const real radius = gather_bytes<double>(in.shape_size, offset) + gather_bytes<double>(in.shape_inflation, offset);
    s.radius = radius;
    if (!Capsule) {
      s.p0 = s.p1 = c;
      return s;
    }
    const real half = gather_bytes<double>(in.shape_size + 1, offset);
    w = w / norm, x = x / norm, y = y / norm, z = z / norm;
    // The capsule's local z axis is the third column of the rotation matrix of q.
    const V3 axis{splat(2.0) * (x * z + w * y), splat(2.0) * (y * z - w * x),
                  splat(1.0) - splat(2.0) * (x * x + y * y)};
    s.p0 = sub(c, scale(half, axis));
    s.p1 = add(c, scale(half, axis));
    return s;
  }

  /// Closest points ca on A's segment and cb on B's (closest_points_segments in closed_forms.hpp, as selects).
  template <bool CapsuleA, bool CapsuleB>
  static void closest_points(const Side& A, const Side& B, V3& ca, V3& cb) {
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
  static std::size_t run(const PairView& in, const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                         const ResultView& out, std::uint32_t* fallback) {
    std::size_t fallbacks = 0;
    if (in.shape_count == 0) {
      for (std::size_t k = 0; k < n; ++k) fallback[fallbacks++] = pairs[k];
      return fallbacks;
    }
    const bool distance = query.level >= QueryLevel::distance, points = query.level >= QueryLevel::witness;
    for (std::size_t k = 0; k < n; k += W) {
      const int m = n - k < std::size_t(W) ? int(n - k) : W;
      std::uint32_t idx[W];
      for (int l = 0; l < W; ++l) idx[l] = pairs[k + std::size_t(l < m ? l : m - 1)];
      const bool consecutive = m == W && idx[W - 1] - idx[0] == std::uint32_t(W - 1);  // pairs are ascending
      const Side A = load_side<CapsuleA>(in, in.shape_a, in.translation_a, in.rotation_a, idx, consecutive);
      const Side B = load_side<CapsuleB>(in, in.shape_b, in.translation_b, in.rotation_b, idx, consecutive);
      V3 ca, cb;
      closest_points<CapsuleA, CapsuleB>(A, B, ca, cb);
      const V3 v = sub(cb, ca);
      const real core = wsqrt<double>(dot(v, v));
      const real signed_distance = (core - A.radius) - B.radius;
      const mask answered = A.valid & B.valid & (core > splat(0.0));
      const std::uint32_t live = (m == W ? ~0u : (1u << m) - 1u) & ((1u << W) - 1u);
      const std::uint32_t mine = lane_bits(answered) & live;
      const bool whole = consecutive && mine == live;
      if (whole) {
        std::uint8_t collide[W];
        const std::uint32_t hits = lane_bits(signed_distance <= splat(query.margin));
        for (int l = 0; l < W; ++l) collide[l] = std::uint8_t((hits >> l) & 1u);
        __builtin_memcpy(out.collide + idx[0], collide, W);
        for (int l = 0; l < W; ++l) out.status[idx[0] + std::uint32_t(l)] = Status::converged;
      } else {
        for (int l = 0; l < m; ++l) {
          if (!((mine >> l) & 1u)) {
            fallback[fallbacks++] = idx[l];
            continue;
          }
          out.status[idx[l]] = Status::converged;
          out.collide[idx[l]] = signed_distance[l] <= query.margin ? 1 : 0;
        }
      }
      if (distance) store(out.distance, idx, whole, signed_distance, mine);
      if (points) {
        const real safe_core = select(answered, core, splat(1.0));
        const V3 normal{v.x / safe_core, v.y / safe_core, v.z / safe_core};
        const V3 wa = add(ca, scale(A.radius, normal)), wb = sub(cb, scale(B.radius, normal));
        const V3* vecs[3] = {&wa, &wb, &normal};
        double* const* dst[3] = {out.witness_a, out.witness_b, out.normal};
        for (int j = 0; j < 3; ++j) {
          store(dst[j][0], idx, whole, vecs[j]->x, mine);
          store(dst[j][1], idx, whole, vecs[j]->y, mine);
          store(dst[j][2], idx, whole, vecs[j]->z, mine);
        }
      }
    }
    return fallbacks;
  }
};
