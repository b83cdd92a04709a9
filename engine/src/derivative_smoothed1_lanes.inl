// Smoothed1Lanes::finish()'s arithmetic (derivative_smoothed1.cpp) for any width of GCC/Clang vector extension V with
// its compare mask type M: included once for the baseline set (V = two lanes, SSE2) and once under AVX2's `#pragma
// GCC target` (four lanes). Each lane does psd_projection()'s and Eigen's H = R * S * R.transpose()'s elementwise
// IEEE operations in their order (-ffp-contract=off: nothing fused), so every set gives the per-pair path's bits.
// The includer declares sqrt_lanes(V), any_lane(M) and blend_lanes(M m, V a, V b) (m ? a : b) before the include.
// No include guard.

namespace {

template <class V, class M> inline __attribute__((always_inline)) V select(M m, V a, V b) {
  return blend_lanes(m, a, b);  // the includer's m ? a : b
}
template <class V, class M> inline __attribute__((always_inline)) V abs_lanes(V x) {
  return (V)((M)x & 0x7FFFFFFFFFFFFFFFll);
}
template <class V, class M> inline __attribute__((always_inline)) V max_lanes(V a, V b) {
  return select<V, M>(a < b, b, a);  // std::max(a, b)
}

// jacobi_rotate() (derivative_support.cpp) in the lanes of `go` where a_pq != 0 (its early return).
template <class V, class M>
inline __attribute__((always_inline)) void rotate_lanes(M go, V& app, V& aqq, V& apq, V& arp, V& arq) {
  go &= apq != 0.0;
  const V theta = (aqq - app) / (2.0 * apq), at = abs_lanes<V, M>(theta);
  V magnitude = 1.0 / (at + sqrt_lanes(at * at + 1.0));
  const M large = at > 1e150;
  if (__builtin_expect(any_lane(large), 0)) magnitude = select<V, M>(large, 0.5 / at, magnitude);
  const V t = (V)((M)magnitude | ((M)theta & (M{} + (-0x7FFFFFFFFFFFFFFFll - 1))));  // copysign(magnitude, theta)
  const V c = 1.0 / sqrt_lanes(t * t + 1.0), s = t * c;
  const V rp = arp, rq = arq;
  app = select<V, M>(go, app - t * apq, app);
  aqq = select<V, M>(go, aqq + t * apq, aqq);
  apq = select<V, M>(go, V{}, apq);
  arp = select<V, M>(go, c * rp - s * rq, rp);
  arq = select<V, M>(go, s * rp + c * rq, rq);
}

// The sum of three products as Eigen's 3x3 products and project()'s loops add them: rows 0-1 (a two-row packet)
// (p0 + p1) + p2, row 2 (the unrolled reduction) p0 + (p1 + p2).
template <class V> inline __attribute__((always_inline)) V sum3(int row, V p0, V p1, V p2) {
  return row < 2 ? (p0 + p1) + p2 : p0 + (p1 + p2);
}

// One side of lanes l .. l + |V|: put(3 i + j, (R psd_projection(S) R^T)(i, j)).
template <class V, class M, class Put>
inline __attribute__((always_inline)) void world_hessian_lanes(const Smoothed1Lanes& in, int side, std::size_t l,
                                                               const Put& put) {
  const auto load = [&](const double* p) {
    V v;
    __builtin_memcpy(&v, p + l, sizeof v);
    return v;
  };
  const V h00 = load(in.S[side][0]), h11 = load(in.S[side][1]), h22 = load(in.S[side][2]);
  const V h01 = load(in.S[side][3]), h02 = load(in.S[side][4]), h12 = load(in.S[side][5]);
  const V Hf[3][3] = {{h00, h01, h02}, {h01, h11, h12}, {h02, h12, h22}};
  // needs_eigenvalues(): not positive definite by the leading minors (each well above its rounding), and finite.
  M needs;
  {
    const V m2 = h00 * h11 - h01 * h01, m2_size = abs_lanes<V, M>(h00 * h11) + h01 * h01;
    const V c0 = h11 * h22 - h12 * h12, c1 = h01 * h22 - h12 * h02, c2 = h01 * h12 - h11 * h02;
    const V det = h00 * c0 - h01 * c1 + h02 * c2;
    const auto a = [](V x) { return abs_lanes<V, M>(x); };
    const V det_size = a(h00) * (a(h11 * h22) + h12 * h12) + a(h01) * (a(h01 * h22) + a(h12 * h02)) +
                       a(h02) * (a(h01 * h12) + a(h11 * h02));
    const M definite = (h00 > 0.0) & (m2 > 1e-12 * m2_size) & (det > 1e-12 * det_size);
    const M finite = ((h00 - h00) == 0.0) & ((h11 - h11) == 0.0) & ((h22 - h22) == 0.0) & ((h01 - h01) == 0.0) &
                     ((h02 - h02) == 0.0) & ((h12 - h12) == 0.0);
    needs = ~definite & finite;
  }
  V P[3][3];
  if (!any_lane(needs)) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) P[i][j] = Hf[i][j];
  } else {
    // symmetric_eigenvalues(): cyclic sweeps until the lane's off-diagonal test fails (a stopped lane keeps its
    // values, so its test stays failed, as the scalar loop's break).
    V a00 = h00, a11 = h11, a22 = h22, a01 = h01, a02 = h02, a12 = h12;
    for (int sweep = 0; sweep < 32; ++sweep) {
      const V off = max_lanes<V, M>(max_lanes<V, M>(abs_lanes<V, M>(a01), abs_lanes<V, M>(a02)), abs_lanes<V, M>(a12));
      const V diagonal =
          max_lanes<V, M>(max_lanes<V, M>(abs_lanes<V, M>(a00), abs_lanes<V, M>(a11)), abs_lanes<V, M>(a22));
      const M go = needs & (off > 1e-18 * diagonal);
      if (!any_lane(go)) break;
      rotate_lanes<V, M>(go, a00, a11, a01, a02, a12);  // (p, q, r) = (0, 1, 2)
      rotate_lanes<V, M>(go, a00, a22, a02, a01, a12);  // (0, 2, 1)
      rotate_lanes<V, M>(go, a11, a22, a12, a01, a02);  // (1, 2, 0)
    }
    // project(): the eigenvalues sorted l0 >= l1 >= l2 by its three swaps.
    V l0 = a00, l1 = a11, l2 = a22;
    const auto order = [](V& hi, V& lo) {
      const M swap = lo > hi;
      const V h = select<V, M>(swap, lo, hi), w = select<V, M>(swap, hi, lo);
      hi = h, lo = w;
    };
    order(l0, l1), order(l1, l2), order(l0, l1);
    const M one = l1 >= 0.0;
    const V x = select<V, M>(one, l0, l1), y = select<V, M>(one, l1, l2);
    const V den = select<V, M>(one, (l2 - l0) * (l2 - l1), (l0 - l1) * (l0 - l2));
    V A[3][3], B[3][3], Q[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double d = i == j ? 1.0 : 0.0;  // x I's entries x * 1 and x * 0 (a signed zero), as project()
        A[i][j] = Hf[i][j] - x * d;
        B[i][j] = Hf[i][j] - y * d;
      }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const V q = sum3(i, A[i][0] * B[0][j], A[i][1] * B[1][j], A[i][2] * B[2][j]) / den;
        Q[i][j] = select<V, M>(one, Hf[i][j] - l2 * q, l0 * q);
      }
    // l2 >= 0: H itself; l0 <= 0: zero; else the symmetrised projector sum. Lanes without eigenvalues keep H.
    const M keep = ~needs | (l2 >= 0.0), zero = ~keep & (l0 <= 0.0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        P[i][j] = select<V, M>(keep, Hf[i][j], select<V, M>(zero, V{}, 0.5 * (Q[i][j] + Q[j][i])));
  }
  // R P R^T as Eigen evaluates the per-pair path's assignment g.H = R * P * R.transpose() (found by a bitwise
  // comparison on random matrices): T = R P (rows 0-1 (p0 + p1) + p2, row 2 p0 + (p1 + p2)), then T R^T with every
  // entry p0 + (p1 + p2). (A Matrix3d constructed from the same expression sums T R^T by rows as R P: other bits.)
  V R[3][3], T[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = load(in.R[side][3 * i + j]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) T[i][j] = sum3(i, R[i][0] * P[0][j], R[i][1] * P[1][j], R[i][2] * P[2][j]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) put(3 * i + j, sum3(2, T[i][0] * R[j][0], T[i][1] * R[j][1], T[i][2] * R[j][2]));
}

// Both sides of the lanes l .. l + |V| into lanes.a.H0 / .b.H0: whole registers where every lane is pending.
template <class V, class M> void finish_lanes(const Smoothed1Lanes& in, std::size_t l, SmoothLanes& lanes) {
  constexpr std::size_t W = sizeof(V) / sizeof(double);
  const unsigned mask = (in.pending >> l) & ((1u << W) - 1);
  for (int side = 0; side < 2; ++side) {
    SmoothLanes::Side& out = side == 0 ? lanes.a : lanes.b;
    if (mask == (1u << W) - 1) {
      world_hessian_lanes<V, M>(in, side, l, [&](int e, V h) { __builtin_memcpy(&out.H0[e][l], &h, sizeof h); });
    } else {
      world_hessian_lanes<V, M>(in, side, l, [&](int e, V h) {
        for (std::size_t k = 0; k < W; ++k)
          if (mask >> k & 1) out.H0[e][l + k] = h[k];
      });
    }
  }
}

}  // namespace
