// Box-box boolean by the separating-axis theorem over the 15 candidate axes (Gottschalk, Lin, Manocha, "OBBTree",
// SIGGRAPH 1996), W pairs per register straight from their world poses: B's rotation and centre in A's frame,
// then all 15 tests as lane masks (no early exit: a register takes every test). |R| is padded by kSatPaddingUlps
// as in boxes_intersect() (kernels/closed_forms.hpp). Plain boxes only (the caller runs this at
// QueryLevel::boolean with a zero margin, like the scalar closed form); inflated boxes and invalid input go back
// to the caller.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_pairs.inl.

struct WideBoxes : PairLanes {
  static std::size_t run(const PairView& in_arg, const std::uint32_t* pairs, std::size_t n,
                         const ResultView& out_arg, std::uint32_t* fallback) {
    const PairView in = in_arg;  // local copies, as in WideSegments::run
    const ResultView out = out_arg;
    std::size_t fallbacks = 0;
    if (in.shape_count == 0) {
      for (std::size_t k = 0; k < n; ++k) fallback[fallbacks++] = pairs[k];
      return fallbacks;
    }
    for (std::size_t k = 0; k < n; k += W) {
      const Block b = block(pairs, n, k);
      if (b.consecutive) answer<true>(in, b, out, fallback, fallbacks);
      else answer<false>(in, b, out, fallback, fallbacks);
    }
    return fallbacks;
  }

  /// One block of W pairs.
  template <bool Consecutive>
  __attribute__((always_inline)) static void answer(const PairView& in, const Block& b, const ResultView& out,
                                                    std::uint32_t* fallback, std::size_t& fallbacks) {
    const real zero = splat(0.0), pad = splat(kSatPaddingUlps * std::numeric_limits<double>::epsilon());
    Pose pa = load_pose<Consecutive>(in, in.shape_a, in.translation_a, in.rotation_a, b.idx);
    Pose pb = load_pose<Consecutive>(in, in.shape_b, in.translation_b, in.rotation_b, b.idx);
    const mask answered = pa.valid & pb.valid & (field(in.shape_inflation, pa) == zero) &
                          (field(in.shape_inflation, pb) == zero);
    const real ha[3] = {field(in.shape_size[0], pa), field(in.shape_size[1], pa), field(in.shape_size[2], pa)};
    const real hb[3] = {field(in.shape_size[0], pb), field(in.shape_size[1], pb), field(in.shape_size[2], pb)};
    normalize(pa);
    normalize(pb);
    // B's rotation in A's frame is that of conj(qa) qb; B's centre in A's frame is d rotated by conj(qa):
    // d - 2 w (a x d) + 2 a x (a x d) for qa = (w, a). Fewer operations (and registers) than Ra^T Rb.
    Pose rel = pb;
    rel.w = ((pa.w * pb.w + pa.x * pb.x) + pa.y * pb.y) + pa.z * pb.z;
    rel.x = ((pa.w * pb.x - pa.x * pb.w) - pa.y * pb.z) + pa.z * pb.y;
    rel.y = ((pa.w * pb.y - pa.y * pb.w) - pa.z * pb.x) + pa.x * pb.z;
    rel.z = ((pa.w * pb.z - pa.z * pb.w) - pa.x * pb.y) + pa.y * pb.x;
    const V3 d = sub(pb.t, pa.t), axis{pa.x, pa.y, pa.z};
    const V3 e = cross(axis, d), f = cross(axis, e);
    const real two = splat(2.0);
    const real t[3] = {(d.x - two * pa.w * e.x) + two * f.x, (d.y - two * pa.w * e.y) + two * f.y,
                       (d.z - two * pa.w * e.z) + two * f.z};
    real R[3][3], absR[3][3];
    for (int j = 0; j < 3; ++j) {
      const V3 c = column(rel, j);
      const real col[3] = {c.x, c.y, c.z};
      for (int i = 0; i < 3; ++i) {
        R[i][j] = col[i];
        absR[i][j] = abs(col[i]) + pad;
      }
    }
    mask separated{};
    for (int i = 0; i < 3; ++i)  // A's face normals
      separated |= abs(t[i]) > ha[i] + ((hb[0] * absR[i][0] + hb[1] * absR[i][1]) + hb[2] * absR[i][2]);
    for (int j = 0; j < 3; ++j)  // B's face normals
      separated |= abs((t[0] * R[0][j] + t[1] * R[1][j]) + t[2] * R[2][j]) >
                   ((ha[0] * absR[0][j] + ha[1] * absR[1][j]) + ha[2] * absR[2][j]) + hb[j];
    for (int i = 0; i < 3; ++i) {  // edge-edge axes e_i x (R e_j), in A's frame
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
      for (int j = 0; j < 3; ++j) {
        const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        const real dist = abs(t[i2] * R[i1][j] - t[i1] * R[i2][j]);
        const real ra = ha[i1] * absR[i2][j] + ha[i2] * absR[i1][j];
        const real rb = hb[j1] * absR[i][j2] + hb[j2] * absR[i][j1];
        separated |= dist > ra + rb;
      }
    }
    const std::uint32_t mine = lane_bits(answered) & b.live;
    const bool whole = write_collide(b, mine, ~separated, out, fallback, fallbacks);
    write_defaults(b, whole, mine, out);
  }
};
