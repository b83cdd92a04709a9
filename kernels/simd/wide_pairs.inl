// Lane helpers shared by the SIMD closed forms (wide_segments.inl, wide_boxes.inl) and the batch-array GJK
// (wide_gjk_pairs.inl): 3-vectors of lanes, loads and stores at pair indices, shape fields gathered from the
// ShapeTable's per-shape arrays, and world poses with the executor's validity rule.
//
// No include guard: included once per instruction set by isa_body.inl, after wide.hpp, inside the ISA namespace.

struct PairLanes {
  using real = wreal<double>;
  using mask = wmask<double>;
  using Int = typename Wide<double>::Int;
  static constexpr int W = Wide<double>::W;

  struct V3 {
    real x, y, z;
  };
  /// `real` at any double-aligned address: a plain vector load / store of the lanes (GCC vector types alias their
  /// element type). The same code as a memcpy into a local where GCC sees through it; it states the intent and
  /// leaves no local in memory for the optimiser to keep.
  typedef double unaligned_real __attribute__((vector_size(sizeof(double) * W), aligned(alignof(double))));
  static real splat(double v) { return real{} + v; }
  static V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  static V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static V3 scale(real s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
  static real dot(const V3& a, const V3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
  static V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  /// |v|: the sign bit cleared (vector casts between same-size types reinterpret the bits).
  static real abs(real v) { return real(mask(v) & (mask{} + Int(0x7fffffffffffffffLL))); }

  /// Lane l = a[idx[l]]: one vector load when the indices are consecutive. The closed forms pass `Consecutive`
  /// as a template argument so that their consecutive blocks compile to straight vector loads, without a branch
  /// per load and with the pointers free to stay in registers.
  template <bool Consecutive> static real load(const double* a, const std::uint32_t* idx) {
    real r;
    if constexpr (Consecutive) {
      r = *reinterpret_cast<const unaligned_real*>(a + idx[0]);
    } else {
      for (int l = 0; l < W; ++l) r[l] = a[idx[l]];
    }
    return r;
  }
  /// a[idx[l]] = lane l for the lanes set in `lanes` (all of them when `whole`: one vector store).
  static void store(double* a, const std::uint32_t* idx, bool whole, real v, std::uint32_t lanes) {
    if (whole) {
      *reinterpret_cast<unaligned_real*>(a + idx[0]) = v;
    } else {
      for (int l = 0; l < W; ++l)
        if ((lanes >> l) & 1u) a[idx[l]] = v[l];
    }
  }

  /// One side of W pairs: the world pose (q as given, with its norm) and the byte offset of the shape's entry in
  /// the ShapeTable's per-shape arrays of doubles (PairView::shape_size, ...). `valid`: the executor's rule
  /// (detail::normalize_unit_quaternion in engine/src/validate.hpp, with the same norm): q finite with
  /// | |q| - 1 | <= kUnitTolerance (NaN and infinite components fail both comparisons), t within the input limit,
  /// shape index in range (out-of-range lanes read shape 0).
  struct Pose {
    V3 t;
    real w, x, y, z, norm;
    mask shape, valid;
  };
  // Always inlined: with several kernels calling them, GCC stops inlining these on its own, and the closed forms'
  // per-pair cost grows by a third (the numbers are in the commit that added the attribute).
  template <bool Consecutive>
  __attribute__((always_inline)) static Pose load_pose(const PairView& in, const std::uint32_t* shape_index,
                                                       const double* const t[3], const double* const q[4],
                                                       const std::uint32_t* idx) {
    Pose p;
    p.t = {load<Consecutive>(t[0], idx), load<Consecutive>(t[1], idx), load<Consecutive>(t[2], idx)};
    p.w = load<Consecutive>(q[0], idx), p.x = load<Consecutive>(q[1], idx), p.y = load<Consecutive>(q[2], idx),
    p.z = load<Consecutive>(q[3], idx);
    p.norm = wsqrt<double>(((p.w * p.w + p.x * p.x) + p.y * p.y) + p.z * p.z);
    const real deviation = p.norm - splat(1.0);
    // The translation limit (detail::translation_in_range): |x| + |y| + |z| <= kMaxLength, false for NaN and
    // infinite components: one comparison for three.
    p.valid = (deviation <= splat(kUnitTolerance)) & (deviation >= splat(-kUnitTolerance)) &
              (((abs(p.t.x) + abs(p.t.y)) + abs(p.t.z)) <= splat(kMaxLength));
    typedef std::uint32_t lanes32 __attribute__((vector_size(sizeof(std::uint32_t) * W)));
    lanes32 raw;
    if constexpr (Consecutive) {
      __builtin_memcpy(&raw, shape_index + idx[0], sizeof raw);
    } else {
      for (int l = 0; l < W; ++l) raw[l] = shape_index[idx[l]];
    }
    const mask shape = __builtin_convertvector(raw, mask);  // zero-extended to 64-bit lanes
    const mask in_range = shape < (mask{} + Int(in.shape_count));
    p.valid &= in_range;
    p.shape = select(in_range, shape, mask{}) << 3;  // x sizeof(double)
    return p;
  }
  static Pose load_pose(const PairView& in, const std::uint32_t* shape_index, const double* const t[3],
                        const double* const q[4], const std::uint32_t* idx, bool consecutive) {
    return consecutive ? load_pose<true>(in, shape_index, t, q, idx) : load_pose<false>(in, shape_index, t, q, idx);
  }
  /// A per-shape array's entry (e.g. in.shape_size[1]) for each lane's shape.
  static real field(const double* base, const Pose& p) { return gather_bytes<double>(base, p.shape); }

  /// q / |q| (the executor normalises every quaternion it accepts).
  static void normalize(Pose& p) {
    p.w = p.w / p.norm, p.x = p.x / p.norm, p.y = p.y / p.norm, p.z = p.z / p.norm;
  }
  /// Column j of the rotation matrix of a normalised q.
  static V3 column(const Pose& p, int j) {
    const real w = p.w, x = p.x, y = p.y, z = p.z;
    const real one = splat(1.0), two = splat(2.0);
    if (j == 0) return {one - two * (y * y + z * z), two * (x * y + w * z), two * (x * z - w * y)};
    if (j == 1) return {two * (x * y - w * z), one - two * (x * x + z * z), two * (y * z + w * x)};
    return {two * (x * z + w * y), two * (y * z - w * x), one - two * (x * x + y * y)};
  }

  /// Block bookkeeping: the W pair indices of block k (the last block repeats its last pair), which lanes are
  /// real, and whether the indices are consecutive (pairs are ascending).
  struct Block {
    std::uint32_t idx[W];
    int lanes = 0;
    std::uint32_t live = 0;
    bool consecutive = false;
  };
  static Block block(const std::uint32_t* pairs, std::size_t n, std::size_t k) {
    Block b;
    if (n - k >= std::size_t(W)) {  // full block: a straight copy (one vector move), no per-lane clamp
      __builtin_memcpy(b.idx, pairs + k, sizeof b.idx);
      b.lanes = W;
      b.live = (1u << W) - 1u;
      b.consecutive = b.idx[W - 1] - b.idx[0] == std::uint32_t(W - 1);
      return b;
    }
    b.lanes = int(n - k);
    for (int l = 0; l < W; ++l) b.idx[l] = pairs[k + std::size_t(l < b.lanes ? l : b.lanes - 1)];
    b.live = (1u << b.lanes) - 1u;  // W <= 16
    return b;
  }

  /// What the closed forms leave NaN / 0 (the executor does not pre-fill their pairs): the search direction (closed
  /// forms have none) and iterations 0, for the answered lanes `mine`. The arrays of values the query level does not
  /// compute are empty (PairResults), so nothing is written for them.
  __attribute__((always_inline)) static void write_defaults(const Block& b, bool whole, std::uint32_t mine,
                                                            const ResultView& out) {
    const real nan = splat(std::numeric_limits<double>::quiet_NaN());
    for (int c = 0; c < 3; ++c) store(out.direction[c], b.idx, whole, nan, mine);
    if (whole) {
      __builtin_memset(out.iterations + b.idx[0], 0, sizeof(std::int32_t) * W);
    } else {
      for (int l = 0; l < W; ++l)
        if ((mine >> l) & 1u) out.iterations[b.idx[l]] = 0;
    }
  }

  /// Byte l = bit l of `bits` (0 or 1), for up to 8 lanes. Each nibble spreads by one multiply: bit i of the
  /// nibble, shifted by 7 i, lands on bit 8 i, and the four shifted copies do not overlap (no carries).
  static std::uint64_t bits_to_bytes(std::uint32_t bits) {
    const auto spread = [](std::uint32_t nibble) { return std::uint64_t((nibble * 0x204081u) & 0x01010101u); };
    return spread(bits & 15u) | (spread((bits >> 4) & 15u) << 32);
  }
  static_assert(W <= 8, "bits_to_bytes covers 8 lanes");

  /// Writes status converged and collide for the answered lanes (`mine`), appends the others to `fallback`.
  /// Returns whether the block was answered whole with consecutive indices (vector stores allowed).
  static bool write_collide(const Block& b, std::uint32_t mine, mask collide, const ResultView& out,
                            std::uint32_t* fallback, std::size_t& fallbacks) {
    const std::uint32_t hits = lane_bits(collide);
    if (b.consecutive && mine == b.live) {
      const std::uint64_t bytes = bits_to_bytes(hits);  // little-endian: byte l = bit l
      __builtin_memcpy(out.collide + b.idx[0], &bytes, W);
      __builtin_memset(out.status + b.idx[0], int(Status::converged), W);
      return true;
    }
    for (int l = 0; l < b.lanes; ++l) {
      if (!((mine >> l) & 1u)) {
        fallback[fallbacks++] = b.idx[l];
        continue;
      }
      out.status[b.idx[l]] = Status::converged;
      out.collide[b.idx[l]] = std::uint8_t((hits >> l) & 1u);
    }
    return false;
  }
};
