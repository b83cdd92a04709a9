// The smoothed0 estimator of up to 8 pairs mapped to the world, one pair per lane (derivative_smoothed0.cpp's
// FinishLanes). Included once per instruction set there, inside a namespace of its own and under that set's
// `#pragma GCC target`: 8-lane vectors are one AVX-512 register, two AVX2 or four SSE2 registers. Every lane does,
// in their order, the operations of the scalar finish_pair() this replaced (elementwise IEEE operations, no
// contraction: -ffp-contract=off), so every set writes the same bits. Everything here has internal linkage and is
// inlined: no AVX code can be shared with baseline code through a weak symbol.
//
// No include guard.

namespace {

typedef double V __attribute__((vector_size(64)));

inline __attribute__((always_inline)) V load(const double* p) {
  V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline __attribute__((always_inline)) void store(double* p, const V& v) { __builtin_memcpy(p, &v, sizeof v); }

/// Writes the 120 derivative entries of lanes 0 .. 7 to out[e][at .. at + 8) (StoreBlock's entry order).
void finish_lanes(const FinishIn& in, double* const* out, std::size_t at) {
  const V valid = load(in.valid), s_t = load(in.s_t), s_w = load(in.s_w);
  V Ra[3][3];
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) Ra[r][q] = load(in.Ra[3 * r + q]);
  // The noise moved b about its own origin t_b: a world twist (v, w) is the noise coordinates (v - [t_b]x w, w).
  const V tx = load(in.tb[0]), ty = load(in.tb[1]), tz = load(in.tb[2]), zero = {};
  const V S[3][3] = {{zero, -tz, ty}, {tz, zero, -tx}, {-ty, tx, zero}};  // skew(t_b), +0.0 on the diagonal
  // G = sums / valid, divided by the noise scale: the score of the Gaussian is S^-1 z.
  const auto scaled = [&](int e, int r) __attribute__((always_inline)) {
    return load(in.G[e][r]) / valid / (e < 3 ? s_t : s_w);
  };
  // One row of G (already in the world for the point and normal rows) to b's twist: each half times Ra^T, then
  // minus the translation half times [t_b]x.
  const auto twist = [&](const V (&col)[6], V (&w)[6]) __attribute__((always_inline)) {
    for (int h = 0; h < 6; h += 3)
      for (int q = 0; q < 3; ++q) w[h + q] = (col[h] * Ra[q][0] + col[h + 1] * Ra[q][1]) + col[h + 2] * Ra[q][2];
    for (int q = 0; q < 3; ++q) w[3 + q] -= (w[0] * S[0][q] + w[1] * S[1][q]) + w[2] * S[2][q];
  };
  {
    V col[6], w[6];
    for (int e = 0; e < 6; ++e) col[e] = scaled(e, 0);
    twist(col, w);
    for (int e = 0; e < 6; ++e) store(out[store_at::distance_a + e] + at, -w[e]), store(out[store_at::distance_b + e] + at, w[e]);
  }
  constexpr int kB[3] = {store_at::witness_a_b, store_at::witness_b_b, store_at::normal_b};
  constexpr int kA[3] = {store_at::witness_a_a, store_at::witness_b_a, store_at::normal_a};
  for (int k = 0; k < 3; ++k) {  // witness a, witness b, normal: rows 1 + 3k .. 3 + 3k
    const int r0 = 1 + 3 * k;
    V M[3][6];  // Ra times the block (Eigen's row 2 after its 2-row packet: a0 + (a1 + a2))
    for (int e = 0; e < 6; ++e) {
      const V g0 = scaled(e, r0), g1 = scaled(e, r0 + 1), g2 = scaled(e, r0 + 2);
      for (int q = 0; q < 2; ++q) M[q][e] = (Ra[q][0] * g0 + Ra[q][1] * g1) + Ra[q][2] * g2;
      M[2][e] = Ra[2][0] * g0 + (Ra[2][1] * g1 + Ra[2][2] * g2);
    }
    // The a-twist block: [I, -[x]x] - the b-twist block (rigid_motion(); [0, -[n]x] for the normal), -[x]x with
    // rigid_motion()'s -0.0 diagonal.
    const V x0 = load(in.x[k][0]), x1 = load(in.x[k][1]), x2 = load(in.x[k][2]);
    const V nz = {-0.0, -0.0, -0.0, -0.0, -0.0, -0.0, -0.0, -0.0};
    const V minus_skew[3][3] = {{nz, x2, -x1}, {-x2, nz, x0}, {x1, -x0, nz}};
    const double identity = k < 2 ? 1.0 : 0.0;
    for (int j = 0; j < 3; ++j) {
      V w[6];
      twist(M[j], w);
      for (int e = 0; e < 6; ++e) {
        const V m = e < 3 ? zero + (j == e ? identity : 0.0) : minus_skew[j][e - 3];  // +0.0 + c is c
        store(out[kB[k] + 6 * j + e] + at, w[e]);
        store(out[kA[k] + 6 * j + e] + at, m - w[e]);
      }
    }
  }
}

}  // namespace
