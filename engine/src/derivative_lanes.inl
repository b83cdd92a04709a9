// The per-lane bodies of SmoothLanes::solve() and PolytopeLanes::solve() (derivative_ift.cpp), written once for any
// width of GCC/Clang vector extension V: included there once for the baseline set (V = two lanes, SSE2: partial
// blocks and blocks whose columns are not 0, 1, 2, ...) and once per wide set under its `#pragma GCC target` (V =
// eight lanes: one AVX-512 register, two AVX2 registers), as derivative_finish_lanes.inl is for smoothed0. Every
// lane does the same elementwise IEEE operations in the same order (no contraction: -ffp-contract=off), so every set
// writes the same bits. Everything here has internal linkage and is inlined: no AVX code can be shared with
// baseline code through a weak symbol.
//
// The includer declares sqrt_lanes(V) (its set's vector square root), select_positive(z, a, b) (z > 0 ? a : b
// lane by lane) and, for the 8-lane sets, store_lanes(p, at, v) (p[at .. at + 8) = v) before the include.
//
// No include guard.

namespace {

template <class V> inline __attribute__((always_inline)) V load(const double* p) {
  V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

// Lanes l .. l + |V| of the three rows of a lane array (a vector per lane).
template <class V, std::size_t N>
inline __attribute__((always_inline)) void load3(const double (&rows)[3][N], std::size_t l, V (&v)[3]) {
  for (int i = 0; i < 3; ++i) v[i] = load<V>(&rows[i][l]);
}

// Writes the 120 entries of a register of lanes through put(e, value): the distance gradients by the envelope
// theorem from n, x_a, x_b, and for each entry (i, j) of the 3x6 derivatives with respect to the twist of a, given
// by entry(i, j, wa, wb, dn) (dx_a/dxi_a, dx_b/dxi_a, dn/dxi_a), those and the twist of b's by the rigid-motion
// identity (write_from_twist_a()'s order and formulas). n(i), xa(i), xb(i) return coordinate i (a register, or a
// load where the caller wants its operands read from memory at each use); the entries go column by column (j outer),
// so that a caller can compute its operands one column at a time (polytope_lanes()).
// kNormalB: only normal_wrt_b (the 18 entries from store_at::normal_b), the smoothed0 samples' first-order start
// (dn/dxi_b); the other entries are neither computed nor written.
template <bool kNormalB = false, class Put, class Vec, class Entry>
inline __attribute__((always_inline)) void put_outputs(const Put& put, const Vec& n, const Vec& xa, const Vec& xb,
                                                       const Entry& entry) {
  using V = decltype(n(0));
  // put() for the entries kNormalB keeps: after unrolling, e is a constant and the test folds away.
  const auto keep = [&](int e, const V& v) {
    if (!kNormalB || e >= store_at::normal_b) put(e, v);
  };
  keep(0, -n(0)), keep(1, -n(1)), keep(2, -n(2));
  keep(3, n(1) * xa(2) - n(2) * xa(1)), keep(4, n(2) * xa(0) - n(0) * xa(2)), keep(5, n(0) * xa(1) - n(1) * xa(0));
  keep(6, n(0)), keep(7, n(1)), keep(8, n(2));
  keep(9, xb(1) * n(2) - xb(2) * n(1)), keep(10, xb(2) * n(0) - xb(0) * n(2)), keep(11, xb(0) * n(1) - xb(1) * n(0));
  // Unrolled: with (i, j) constants the case tests vanish and the operands stay in registers; rolled, GCC kept
  // this a loop over stack arrays with the tests inside (~2.8x the instructions of the PolytopeLanes solve).
#pragma GCC unroll 6
  for (int j = 0; j < 6; ++j)
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i) {
      const int e = 6 * i + j;
      V wa, wb, dn;
      entry(i, j, wa, wb, dn);
      keep(store_at::witness_a_a + e, wa);
      keep(store_at::witness_b_a + e, wb);
      keep(store_at::normal_a + e, dn);
      // The twist of b: the rigid motions [I, -[x]x] (points) and [0, -[n]x] (normal) minus the above.
      if (j < 3) {
        const double one = i == j ? 1.0 : 0.0;
        keep(store_at::witness_a_b + e, one - wa), keep(store_at::witness_b_b + e, one - wb);
        keep(store_at::normal_b + e, 0.0 - dn);
      } else if (j - 3 == i) {
        keep(store_at::witness_a_b + e, 0.0 - wa), keep(store_at::witness_b_b + e, 0.0 - wb);
        keep(store_at::normal_b + e, 0.0 - dn);
      } else {
        const int k = j - 3, other = 3 - i - k;
        // -[x]x(i, k) = eps(i, k, other) x_other
        if ((i + 1) % 3 == k) {
          keep(store_at::witness_a_b + e, xa(other) - wa), keep(store_at::witness_b_b + e, xb(other) - wb);
          keep(store_at::normal_b + e, n(other) - dn);
        } else {
          keep(store_at::witness_a_b + e, -xa(other) - wa), keep(store_at::witness_b_b + e, -xb(other) - wb);
          keep(store_at::normal_b + e, -n(other) - dn);
        }
      }
    }
}

// Separated pairs without flats (the smooth common case, every ellipsoid pair): M0 = sd I + H_a + H_b >= sd I is
// symmetric positive definite, so K is its explicit inverse (cofactors over the determinant, which is >= sd^3 > 0).
// Only the twist of a is solved, y = K F_a = [K, K Fa_w] (Fa_w = H_a [n]x - [x_a]x), and
//   dx_b/dxi_a = H_b y,   dx_a/dxi_a = dx_b/dxi_a + sd y   (dz = -sd y; equal to F_a - H_a y since H_a K + H_b K =
//   I - sd K),   dn/dxi_a = -(I - n n^T) y;
// the twist of b by the rigid-motion identity (put_outputs()). Lanes l .. l + |V| of `s`, written through put.
// kGiven: some lane has a given H0 (SmoothLanes::given); otherwise every H0 is +0 and is not read.
template <bool kNormalB, bool kCurved, bool kGiven, class V, class Put>
inline __attribute__((always_inline)) void smooth_lanes(const SmoothLanes& s, std::size_t l, const Put& put) {
  {
    const V d = load<V>(&s.sd[l]);
    V n[3], xa[3], xb[3];
    load3(s.n, l, n), load3(s.xa, l, xa), load3(s.xb, l, xb);
    // The support-map Jacobians (world_support_jacobian()'s formula and order of operations; it is even in n).
    const auto curvature = [&](const SmoothLanes::Side& side, V (&H)[3][3]) {
      if constexpr (!kCurved) {  // every lane's H is its H0 (see `curved`): ~150 instructions a side fewer
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) H[i][j] = load<V>(&side.H0[3 * i + j][l]) + 0.0;
        return;
      }
      // R = Eigen's q.normalized().toRotationMatrix() with its operations in its order (|q|^2 summed as
      // (x^2 + z^2) + (y^2 + w^2), its SSE2 reduction; each coefficient divided by |q|, q kept where |q|^2 is not
      // > 0): the same bits, checked against Eigen on random quaternions by
      // DerivativesLanes.LaneRotationsGiveEigensBits. A side without a curved shape (q = 0) gets the identity,
      // whose B with radii2 = 0 is +0 everywhere, as the zero matrix's was.
      V R[3][3], B[3][3], Bn[3];
      {
        V c[4];
        for (int k = 0; k < 4; ++k) c[k] = load<V>(&side.q[k][l]);
        const V z = (c[0] * c[0] + c[2] * c[2]) + (c[1] * c[1] + c[3] * c[3]);
        const V root = sqrt_lanes(z);
        const V x = select_positive(z, c[0] / root, c[0]), y = select_positive(z, c[1] / root, c[1]);
        const V zq = select_positive(z, c[2] / root, c[2]), w = select_positive(z, c[3] / root, c[3]);
        const V tx = 2.0 * x, ty = 2.0 * y, tz = 2.0 * zq;
        const V twx = tx * w, twy = ty * w, twz = tz * w, txx = tx * x, txy = ty * x, txz = tz * x;
        const V tyy = ty * y, tyz = tz * y, tzz = tz * zq;
        R[0][0] = 1.0 - (tyy + tzz), R[0][1] = txy - twz, R[0][2] = txz + twy;
        R[1][0] = txy + twz, R[1][1] = 1.0 - (txx + tzz), R[1][2] = tyz - twx;
        R[2][0] = txz - twy, R[2][1] = tyz + twx, R[2][2] = 1.0 - (txx + tyy);
      }
      const V D[3] = {load<V>(&side.radii2[0][l]), load<V>(&side.radii2[1][l]), load<V>(&side.radii2[2][l])};
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
          B[i][j] = B[j][i] = R[i][0] * D[0] * R[j][0] + R[i][1] * D[1] * R[j][1] + R[i][2] * D[2] * R[j][2];
      for (int i = 0; i < 3; ++i) Bn[i] = B[i][0] * n[0] + B[i][1] * n[1] + B[i][2] * n[2];
      const V m2 = n[0] * Bn[0] + n[1] * Bn[1] + n[2] * Bn[2];
      const V m = sqrt_lanes(m2);
      const V zero = {};
      const V inv_m = select_positive(m2, 1.0 / m, zero), inv_m3 = inv_m * inv_m * inv_m;
      const V r = load<V>(&side.round[l]);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          H[i][j] = (kGiven ? load<V>(&side.H0[3 * i + j][l]) : zero) + B[i][j] * inv_m -
                    Bn[i] * Bn[j] * inv_m3 + r * ((i == j ? 1.0 : 0.0) - n[i] * n[j]);
    };
    V Ha[3][3], Hb[3][3];
    curvature(s.a, Ha);
    curvature(s.b, Hb);
    // K = M0^-1 from the upper triangle (M0 is symmetric up to the rounding of the world-frame rotations).
    const V m00 = d + Ha[0][0] + Hb[0][0], m11 = d + Ha[1][1] + Hb[1][1], m22 = d + Ha[2][2] + Hb[2][2];
    const V m01 = Ha[0][1] + Hb[0][1], m02 = Ha[0][2] + Hb[0][2], m12 = Ha[1][2] + Hb[1][2];
    const V c00 = m11 * m22 - m12 * m12, c01 = m02 * m12 - m01 * m22, c02 = m01 * m12 - m02 * m11;
    const V c11 = m00 * m22 - m02 * m02, c12 = m01 * m02 - m00 * m12, c22 = m00 * m11 - m01 * m01;
    const V inv = 1.0 / (m00 * c00 + m01 * c01 + m02 * c02);
    const V K[3][3] = {{c00 * inv, c01 * inv, c02 * inv}, {c01 * inv, c11 * inv, c12 * inv},
                       {c02 * inv, c12 * inv, c22 * inv}};
    // Fa_w: row i of H_a [n]x is (row i of H_a) x n; minus [x_a]x.
    V F[3][3];
    for (int i = 0; i < 3; ++i) {
      F[i][0] = Ha[i][1] * n[2] - Ha[i][2] * n[1];
      F[i][1] = Ha[i][2] * n[0] - Ha[i][0] * n[2];
      F[i][2] = Ha[i][0] * n[1] - Ha[i][1] * n[0];
    }
    F[0][1] += xa[2], F[0][2] -= xa[1], F[1][0] -= xa[2], F[1][2] += xa[0], F[2][0] += xa[1], F[2][1] -= xa[0];
    V Y[3][6];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        Y[i][j] = K[i][j];
        Y[i][3 + j] = K[i][0] * F[0][j] + K[i][1] * F[1][j] + K[i][2] * F[2][j];
      }
    V nY[6];
    for (int j = 0; j < 6; ++j) nY[j] = n[0] * Y[0][j] + n[1] * Y[1][j] + n[2] * Y[2][j];
    const auto row = [](const V (&v)[3]) { return [&v](int i) __attribute__((always_inline)) { return v[i]; }; };
    put_outputs<kNormalB>(put, row(n), row(xa), row(xb), [&](int i, int j, V& wa, V& wb, V& dn) {
      wb = Hb[i][0] * Y[0][j] + Hb[i][1] * Y[1][j] + Hb[i][2] * Y[2][j];
      wa = wb + d * Y[i][j];
      dn = n[i] * nY[j] - Y[i][j];
    });
  }
}

// PolytopeLanes' lanes l .. l + |V| (the closed forms of derivative_ift.hpp), written through put.
template <class V, class Put>
inline __attribute__((always_inline)) void polytope_lanes(const PolytopeLanes& lanes, std::size_t l, const Put& put) {
  {
    const V inv = 1.0 / load<V>(&lanes.sd[l]);
    const auto d = [&] { return load<V>(&lanes.sd[l]); };
    const auto row = [l](const double (&rows)[3][PolytopeLanes::kLanes]) {
      return [&rows, l](int i) __attribute__((always_inline)) { return load<V>(&rows[i][l]); };
    };
    const auto n = row(lanes.n), xa = row(lanes.xa), xb = row(lanes.xb);
    const auto Wr = [&](int i, int j) __attribute__((always_inline)) { return load<V>(&lanes.W[3 * i + j][l]); };
    const auto P = [&](int i, int j) __attribute__((always_inline)) { return load<V>(&lanes.P[3 * i + j][l]); };
    const auto Ip = [&](int i, int j) __attribute__((always_inline)) { return (i == j ? 1.0 : 0.0) - P(i, j); };
    // Column j of Y = y and R = F - sd y = [P, -[x_a]x + (I - P) [x_a]x - sd G] (row i of M [x]x is (row i of M) x
    // x), computed when put_outputs() reaches the column (its first row), with every lane array (n, x_a, x_b, sd,
    // P, G, W) read from memory where it is used: all of Y and R (36 registers of 8 lanes), n, x_a and x_b held
    // through the 120 stores were ~250 spills and reloads a block in AVX2 (16 registers, two per 8 lanes); now only
    // a column's Y, R and n . Y are held. The same operations on the same operands as a whole-matrix pass: the same
    // bits. Each Ip entry is recomputed where used (one subtraction with a memory operand) rather than held.
    V Y[3], R[3], nY;
    put_outputs(put, n, xa, xb, [&](int i, int j, V& wa, V& wb, V& dn) {
      if (i == 0) {
        for (int k = 0; k < 3; ++k) {
          if (j < 3) {
            Y[k] = Ip(k, j) * inv;
            R[k] = P(k, j);
          } else {
            const int c0 = j - 3, c1 = (c0 + 1) % 3, c2 = (c0 + 2) % 3;
            const V c = Ip(k, c1) * xa(c2) - Ip(k, c2) * xa(c1);
            const V g = load<V>(&lanes.G[3 * k + c0][l]);
            Y[k] = g - c * inv;
            R[k] = c - d() * g;
            // -[x_a]x: x_2 at (0, 1), -x_1 at (0, 2), -x_2 at (1, 0), x_0 at (1, 2), x_1 at (2, 0), -x_0 at (2, 1).
            if (k != c0) {
              if ((k + 1) % 3 == c0) R[k] += xa(3 - k - c0);
              else R[k] -= xa(3 - k - c0);
            }
          }
        }
        nY = n(0) * Y[0] + n(1) * Y[1] + n(2) * Y[2];
      }
      wb = Wr(i, 0) * R[0] + Wr(i, 1) * R[1] + Wr(i, 2) * R[2];
      wa = wb + d() * Y[i];
      dn = n(i) * nY - Y[i];
    });
  }
}

// A block of kLanes pairs to output columns 0, 1, 2, ..., one register of V: every entry one store(e, v) (the
// includer's: a whole store to out[e] + at, a masked one for a block of fewer pairs, a non-temporal one). `store`
// by value: a copy whose address does not escape keeps its captures in registers; by reference, GCC reloaded out
// and at from the caller's closure after each of the 120 stores (which may alias it): +29 instructions a hull
// pair (callgrind AVX2).
template <class V, bool kNormalB, bool kCurved, bool kGiven, class Store>
void smooth_block(const SmoothLanes& s, const Store store) {
  static_assert(sizeof(V) == SmoothLanes::kLanes * sizeof(double));
  smooth_lanes<kNormalB, kCurved, kGiven, V>(s, 0, store);
}

template <class V, class Store> void polytope_block(const PolytopeLanes& lanes, const Store store) {
  static_assert(sizeof(V) == PolytopeLanes::kLanes * sizeof(double));
  polytope_lanes<V>(lanes, 0, store);
}

}  // namespace
