// The smoothed0 derivatives' perturbed samples, W antithetic pairs of samples per register (engine/src/
// derivative_smoothed0.cpp): the counter-based Gaussian draws (engine/src/counter_rng.hpp's sample_noise(), lane
// by lane: the pair key's SplitMix64 outputs 3k .. 3k + 2, each one float Box-Muller transform) and B's
// perturbed pose in A's frame, E R0 and t0 + s_t z for sample 2k, E^T R0 and t0 - s_t z for its antithetic copy
// 2k+1. Every lane does the scalar code's operations in its order (no FMA contraction), so every instruction set
// gives the bits of engine/src/counter_rng.hpp's sample_noise() and of the scalar build (tested in
// tests/kernels/wide_samples_test.cpp). In scalar code the drawing and the building were a third of a sample's work.
//
// No include guard: included once per instruction set by isa_body.inl.

struct WideSamples {
  static constexpr int W = Wide<double>::W;
  using real = wreal<double>;
  using mask = wmask<double>;  // 64-bit lane integers
  typedef std::uint64_t u64 __attribute__((vector_size(sizeof(real))));

  static u64 splitmix(u64 x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  static real splat(double v) { return real{} + v; }

  /// sin(x) / x and cos(x) for |x| <= pi/4 by their Taylor series to x^16 (remainder below 5e-17): the samples'
  /// rotations, the same bits on every set (plain IEEE operations, no contraction).
  static void sinc_cos_small(real x, real& sinc, real& cos) {
    const real z = x * x;
    sinc = ((((((((-1.0 / 355687428096000.0) * z + 1.0 / 1307674368000.0) * z - 1.0 / 6227020800.0) * z +
                 1.0 / 39916800.0) * z - 1.0 / 362880.0) * z + 1.0 / 5040.0) * z - 1.0 / 120.0) * z + 1.0 / 6.0);
    sinc = 1.0 - z * sinc;
    cos = (((((((1.0 / 20922789888000.0 * z - 1.0 / 87178291200.0) * z + 1.0 / 479001600.0) * z -
                 1.0 / 3628800.0) * z + 1.0 / 40320.0) * z - 1.0 / 720.0) * z + 1.0 / 24.0) * z - 0.5) * z + 1.0;
  }

  /// support_noise()'s float lanes: 2 W of them in a register (lane 2l + i: pair l's transform j + i).
  typedef float fv __attribute__((vector_size(sizeof(real))));
  typedef std::int32_t iv __attribute__((vector_size(sizeof(real))));
  typedef std::uint32_t uv __attribute__((vector_size(sizeof(real))));
  static fv fsqrt(fv a) {
#if BATCHCOL_SIMD_BYTES == 32
    return _mm256_sqrt_ps(a);
#elif BATCHCOL_SIMD_BYTES == 64
    return _mm512_sqrt_ps(a);
#else
    for (int l = 0; l < 2 * W; ++l) a[l] = std::sqrt(a[l]);
    return a;
#endif
  }
  /// counter_rng.hpp's minus_two_log_unit_f(h), lane by lane (the same float operations in the same order).
  static fv minus_two_log_unit_f(uv h) {
    const fv u = (__builtin_convertvector((iv)h, fv) + 1.0f) * 0x1.0p-31f;
    iv bits = (iv)u;
    const iv k = (bits - 0x3F3504F3) >> 23;  // arithmetic: the floor of the exponent offset
    bits -= (iv)((uv)k << 23);
    const fv m = (fv)bits;
    const fv s = (m - 1.0f) / (m + 1.0f), z = s * s;
    const fv p = (((1.0f / 9.0f * z + 1.0f / 7.0f) * z + 1.0f / 5.0f) * z + 1.0f / 3.0f) * z + 1.0f;
    return __builtin_convertvector(k, fv) * static_cast<float>(-2.0 * 0.6931471805599453) - (4.0f * s) * p;
  }
  /// counter_rng.hpp's sincos_turn_f(a), lane by lane; its conditional negations are sign-bit flips.
  static void sincos_turn_f(uv a, fv& sin, fv& cos) {
    const uv q = (a + 0x20000000u) >> 30;
    const iv r = (iv)(a - (q << 30));
    const fv x = __builtin_convertvector(r, fv) * static_cast<float>(6.283185307179586 * 0x1.0p-32), z = x * x;
    const fv sx = x * ((((1.0f / 362880.0f * z - 1.0f / 5040.0f) * z + 1.0f / 120.0f) * z - 1.0f / 6.0f) * z + 1.0f);
    const fv cx = (((1.0f / 40320.0f * z - 1.0f / 720.0f) * z + 1.0f / 24.0f) * z - 0.5f) * z + 1.0f;
    const iv swap = (iv)(q << 31) >> 31;  // all ones for odd q
    sin = (fv)((uv)select(swap, cx, sx) ^ ((q & 2u) << 30));
    cos = (fv)((uv)select(swap, sx, cx) ^ (((q + 1u) & 2u) << 30));
  }
  typedef float f4 __attribute__((vector_size(16)));
  typedef double d4 __attribute__((vector_size(32)));
  /// Pair L's normals of transforms j and j + 1 (lanes 2L, 2L + 1 of g0 and g1) as 4 doubles to dst (one 32-byte
  /// store), or only transform j's 2 when j + 1 is past the last. e and o: g0 and g1 interleaved within each
  /// 16 bytes (unpcklps / unpckhps), so that their 16-byte parts are pair 0, 2, 4, ... and 1, 3, 5, ...'s blocks.
  template <int L> static void store_noise(fv e, fv o, double* dst, bool both) {
    const fv& src = L % 2 == 0 ? e : o;
    const f4 v = __builtin_shufflevector(src, src, 4 * (L / 2), 4 * (L / 2) + 1, 4 * (L / 2) + 2, 4 * (L / 2) + 3);
    // vcvtps2pd ymm, xmm (every SIMD set here has AVX): GCC's own conversion went through two 2-lane conversions,
    // a stack copy and an insert.
    const d4 d = (d4)_mm256_cvtps_pd((__m128)v);
    if (both) std::memcpy(dst, &d, sizeof d);
    else std::memcpy(dst, &d, sizeof d / 2);
  }
  template <int L> static void store_noise_lanes(fv e, fv o, double* out, std::size_t per_pair, int lanes,
                                                 bool both) {
    if constexpr (L < W) {
      if (L >= lanes) return;
      store_noise<L>(e, o, out + std::size_t(L) * per_pair, both);
      store_noise_lanes<L + 1>(e, o, out, per_pair, lanes, both);
    }
  }
  static void store_noise_all(fv g0, fv g1, double* out, std::size_t per_pair, int lanes, bool both) {
#if BATCHCOL_SIMD_BYTES == 32
    const fv e = __builtin_shufflevector(g0, g1, 0, 8, 1, 9, 4, 12, 5, 13);
    const fv o = __builtin_shufflevector(g0, g1, 2, 10, 3, 11, 6, 14, 7, 15);
    store_noise_lanes<0>(e, o, out, per_pair, lanes, both);
#elif BATCHCOL_SIMD_BYTES == 64
    const fv e = __builtin_shufflevector(g0, g1, 0, 16, 1, 17, 4, 20, 5, 21, 8, 24, 9, 25, 12, 28, 13, 29);
    const fv o = __builtin_shufflevector(g0, g1, 2, 18, 3, 19, 6, 22, 7, 23, 10, 26, 11, 27, 14, 30, 15, 31);
    store_noise_lanes<0>(e, o, out, per_pair, lanes, both);
#else
    (void)per_pair, (void)lanes;
    const d4 d = __builtin_convertvector(__builtin_shufflevector(g0, g1, 0, 2, 1, 3), d4);
    if (both) std::memcpy(out, &d, sizeof d);
    else std::memcpy(out, &d, sizeof d / 2);
#endif
  }

  /// engine/src/counter_rng.hpp's support_noise_pair(keys[p], j) for every j < 3 draws of pairs p < `pairs` into
  /// z[6 draws p + 2 j], z[6 draws p + 2 j + 1] (smoothed1's noise of a store block's pairs), W pairs per register:
  /// the lanes are pairs, so their keys are one load and each j one 64-bit mix per lane (no per-lane key set-up).
  /// Two mixes (j, j + 1) fill one float register of 2 W transforms: their 32-bit halves interleave in place
  /// (lane 2l + i: transform j + i of pair l), and pair l's 4 normals are one 32-byte store.
  static void support_noise(const std::uint64_t* keys, std::size_t pairs, std::size_t draws, double* z) {
    const std::size_t per_pair = 6 * draws, transforms = 3 * draws;
    for (std::size_t p0 = 0; p0 < pairs; p0 += W) {
      const int lanes = int(std::min<std::size_t>(W, pairs - p0));
      u64 key{};
      for (int l = 0; l < W; ++l) key[l] = keys[p0 + std::size_t(std::min(l, lanes - 1))];  // padding: unstored
      double* const out = z + p0 * per_pair;
      for (std::size_t j = 0; j < transforms; j += 2) {
        fv g0, g1;
        box_muller_f(splitmix(key + j * 0x9E3779B97F4A7C15ull), splitmix(key + (j + 1) * 0x9E3779B97F4A7C15ull), g0,
                     g1);
        store_noise_all(g0, g1, out + 2 * j, per_pair, lanes, j + 1 < transforms);
      }
    }
  }
  /// support_noise_pair()'s transform of the mixes xa (lane l) and xb (lane l) into float lanes 2l (xa's) and
  /// 2l + 1 (xb's): g0 = radius cos, g1 = radius sin. The 32-bit halves interleave in place (little endian).
  __attribute__((always_inline)) static void box_muller_f(u64 xa, u64 xb, fv& g0, fv& g1) {
    const uv hi = (uv)((xa >> 33) | ((xb >> 1) & 0x7FFFFFFF00000000ull));  // the top 31 bits of each
    const uv lo = (uv)((xa & 0xFFFFFFFFull) | (xb << 32));
    const fv radius = fsqrt(minus_two_log_unit_f(hi));
    fv s, c;
    sincos_turn_f(lo, s, c);
    g0 = radius * c;
    g1 = radius * s;
  }
  /// Float lanes 2l (I = 0) or 2l + 1 (I = 1) of v as W doubles (exact conversions).
  template <int I> static real float_lanes(fv v) {
#if BATCHCOL_SIMD_BYTES == 32
    return (real)_mm256_cvtps_pd((__m128)__builtin_shufflevector(v, v, I, 2 + I, 4 + I, 6 + I));
#elif BATCHCOL_SIMD_BYTES == 64
    return (real)_mm512_cvtps_pd(
        (__m256)__builtin_shufflevector(v, v, I, 2 + I, 4 + I, 6 + I, 8 + I, 10 + I, 12 + I, 14 + I));
#else
    real r;
    r[0] = double(v[I]);
    return r;
#endif
  }
  /// counter_rng.hpp's sample_noise(key, k, z) lane by lane, lane l's start = key + 3 k 0x9E3779B97F4A7C15 (the
  /// SplitMix64 state before its transform 3k): transforms 3k and 3k + 1 share a float register, 3k + 2 fills
  /// half of one. 3 64-bit mixes a lane instead of gaussian_vector<6>'s 8 (2 for the key set-up, 6 uniforms).
  static void sample_noise(u64 start, real (&z)[6]) {
    constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;
    const u64 x0 = splitmix(start), x1 = splitmix(start + kGolden), x2 = splitmix(start + 2 * kGolden);
    fv g0, g1;
    box_muller_f(x0, x1, g0, g1);
    z[0] = float_lanes<0>(g0), z[1] = float_lanes<0>(g1), z[2] = float_lanes<1>(g0), z[3] = float_lanes<1>(g1);
    box_muller_f(x2, x2, g0, g1);
    z[4] = float_lanes<0>(g0), z[5] = float_lanes<0>(g1);
  }
  /// The start state of sample_noise() for antithetic pair k of a pair with key `key`.
  static std::uint64_t noise_start(std::uint64_t key, std::uint64_t k) { return key + 3 * k * 0x9E3779B97F4A7C15ull; }

  typedef double v4 __attribute__((vector_size(32)));
  typedef double v4u __attribute__((vector_size(32), aligned(8)));  // an unaligned load of 4 doubles

  /// One term of the noise sums: (row `plus` minus row `minus`, kept as d) times noise z[.][zk]. An antithetic pair whose two
  /// samples are valid is one term, plus its first sample, minus its copy, z the first's; a valid sample without
  /// its valid copy is (itself minus g0) times its own z.
  struct Term {
    v4 d[3];  // row `plus` minus row `minus`, computed once for both passes
    std::uint32_t zk;
  };
  /// One pass of accumulate() over the terms t[0 .. m): the sums of noise columns F .. F + 2. 9 accumulators, the
  /// difference and the broadcast fit AVX2's 16 registers.
  template <int F>
  static void pass(const Term* t, int m, const double* const* z, double (*G_sums)[12]) {
    // Named vectors, not arrays: GCC kept memcpy-initialised arrays on the stack.
    v4 a0, a1, a2, b0, b1, b2, c0, c1, c2;
    std::memcpy(&a0, G_sums[F], 32), std::memcpy(&a1, G_sums[F] + 4, 32), std::memcpy(&a2, G_sums[F] + 8, 32);
    std::memcpy(&b0, G_sums[F + 1], 32), std::memcpy(&b1, G_sums[F + 1] + 4, 32);
    std::memcpy(&b2, G_sums[F + 1] + 8, 32);
    std::memcpy(&c0, G_sums[F + 2], 32), std::memcpy(&c1, G_sums[F + 2] + 4, 32);
    std::memcpy(&c2, G_sums[F + 2] + 8, 32);
    const double *za = z[F], *zb = z[F + 1], *zc = z[F + 2];
    for (int i = 0; i < m; ++i) {
      const v4 d0 = t[i].d[0], d1 = t[i].d[1], d2 = t[i].d[2];
      const std::uint32_t k = t[i].zk;
      const double a = za[k], b = zb[k], c = zc[k];
      a0 += d0 * a, a1 += d1 * a, a2 += d2 * a;
      b0 += d0 * b, b1 += d1 * b, b2 += d2 * b;
      c0 += d0 * c, c1 += d1 * c, c2 += d2 * c;
    }
    std::memcpy(G_sums[F], &a0, 32), std::memcpy(G_sums[F] + 4, &a1, 32), std::memcpy(G_sums[F] + 8, &a2, 32);
    std::memcpy(G_sums[F + 1], &b0, 32), std::memcpy(G_sums[F + 1] + 4, &b1, 32);
    std::memcpy(G_sums[F + 1] + 8, &b2, 32);
    std::memcpy(G_sums[F + 2], &c0, 32), std::memcpy(G_sums[F + 2] + 4, &c1, 32);
    std::memcpy(G_sums[F + 2] + 8, &c2, 32);
  }

  /// Sample k converged with all values finite.
  __attribute__((always_inline)) static bool valid_sample(const double* values, const Status* status,
                                                          std::size_t k) {
    if (status[k] != Status::converged) return false;
    const v4u* row = reinterpret_cast<const v4u*>(values + 12 * k);
    const v4 v0 = row[0], v1 = row[1], v2 = row[2];
    // x - x is 0 exactly when x is finite (NaN for inf and NaN): one lane compare for the 12 values (a lane
    // of the sum is NaN, hence != 0, as soon as one of its terms is).
    const v4 t = (v0 - v0) + (v1 - v1) + (v2 - v2);
    const auto bad = t != 0.0;
    bool any_bad = false;
    for (int l = 0; l < 4; ++l) any_bad |= bad[l] != 0;
    return !any_bad;
  }

  /// accumulate_samples() (wide_gjk.hpp): a row of 12 is three 4-lane vectors on every set. The values' sums take
  /// the valid samples in sample order; the noise sums take the antithetic pairs in order, a pair with both
  /// samples valid as one term (v_2e - v_2e+1) z_2e (their copy's z is -z_2e exactly, so this is (v_2e - g0) z_2e +
  /// (v_2e+1 - g0) z_2e+1 without g0, and half the multiply-adds), else its valid sample as (v - g0) z (branch
  /// dv2; before, every valid sample's (v - g0) z one after the other: other rounding, the same estimator). A pair
  /// never straddles two calls (blocks end on antithetic pairs), so a pair split over calls gives the same bits.
  static void accumulate(const double* values, const Status* status, const double* const* z, std::size_t count,
                         std::size_t evens, SampleSums& sums) {
    constexpr std::size_t kChunk = 64;  // antithetic pairs per chunk (8 KB of terms; the chunking changes no bit)
    Term t[kChunk];
    for (std::size_t e0 = 0; e0 < evens; e0 += kChunk) {
      const std::size_t e1 = std::min(evens, e0 + kChunk);
      v4 m0, m1, m2;
      std::memcpy(&m0, sums.mean, 32), std::memcpy(&m1, sums.mean + 4, 32), std::memcpy(&m2, sums.mean + 8, 32);
      int m = 0, valid = 0;
      // The terms' differences are taken here, once, rather than in each of the two passes (the same operands:
      // the same bits; ellipsoids M = 16, callgrind AVX2: see the commit).
      const auto term = [&t, &m](const double* plus, const double* minus, std::size_t zk) {
        const v4u* p = reinterpret_cast<const v4u*>(plus);
        const v4u* q = reinterpret_cast<const v4u*>(minus);
        t[m].d[0] = p[0] - q[0], t[m].d[1] = p[1] - q[1], t[m].d[2] = p[2] - q[2];
        t[m++].zk = std::uint32_t(zk);
      };
      for (std::size_t e = e0; e < e1; ++e) {
        const std::size_t ko = evens + e;
        const bool ve = valid_sample(values, status, e), vo = 2 * e + 1 < count && valid_sample(values, status, ko);
        const double* pe = values + 12 * e;
        const double* po = values + 12 * ko;
        if (ve) {
          const v4u* row = reinterpret_cast<const v4u*>(pe);
          m0 += row[0], m1 += row[1], m2 += row[2];
        }
        if (vo) {
          const v4u* row = reinterpret_cast<const v4u*>(po);
          m0 += row[0], m1 += row[1], m2 += row[2];
        }
        valid += int(ve) + int(vo);
        if (ve && vo) term(pe, po, e);
        else if (ve) term(pe, sums.g0, e);
        else if (vo) term(po, sums.g0, ko);
      }
      std::memcpy(sums.mean, &m0, 32), std::memcpy(sums.mean + 4, &m1, 32), std::memcpy(sums.mean + 8, &m2, 32);
      pass<0>(t, m, z, sums.G);
      pass<3>(t, m, z, sums.G);
      sums.valid += valid;
    }
  }

  /// A register's plan values when its lanes belong to several pairs (small M: M / 2 < W): each field one vector,
  /// lane l the value of its own pair's plan. Every lane then does the single-plan operations with its own values
  /// (a double times a register and a register times a register are the same IEEE operation per lane).
  struct LanePlan {
    real R0[9], t0[3], n0[3], first[3], P[18], translation, rotation;
    mask predict;
  };
  static bool predicts(const SamplePlan& p) { return p.predict; }
  static bool predicts(const LanePlan& p) { return any(p.predict); }
  /// The first GJK direction's coordinate r: -(n0 + P z) where the pair predicts, else its `first`.
  static real first_direction(const SamplePlan& p, int r, const real& predicted) {
    return p.predict ? predicted : splat(p.first[r]);
  }
  static real first_direction(const LanePlan& p, int r, const real& predicted) {
    return select(p.predict, predicted, p.first[r]);
  }

  /// One register of samples from their noise z: B's perturbed poses (E R0, t0 + s_t z) and antithetic copies
  /// (E^T R0, t0 - s_t z), first directions and noise, each array's register stored by put(array, register, n)
  /// (n = lanes, odd_lanes: the lanes to store).
  // GCC 12 reports -Wuninitialized inside its own _mm512_sqrt_pd (the `__m512d __Y = __Y;` of
  // _mm512_undefined_pd(), GCC bug 105593, fixed in GCC 13) once this function is a template of its own; the
  // operand is an intentionally undefined pass-through that the unmasked sqrt never reads.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
  // Always inlined: out of line, the single-plan registers' z and stores went through memory (M = 16, AVX2: +350
  // instructions per register, callgrind).
  template <class Plan, class Put>
  __attribute__((always_inline)) static void poses(const Plan& p, const real (&z)[6], const Put& put, int lanes,
                                                   int odd_lanes, const SampleArrays& even, const SampleArrays& odd) {
    // exp([w]x) through the unit quaternion (cos h, sin(h) w / (2h)), h = |w| / 2 (the engine's rotation_exp).
    const real w0 = p.rotation * z[3], w1 = p.rotation * z[4], w2 = p.rotation * z[5];
    const real angle2 = (w0 * w0 + w1 * w1) + w2 * w2;
    const real h = 0.5 * wsqrt<double>(angle2);
    real sinc, c;
    sinc_cos_small(h, sinc, c);
    const mask wide = h > 0.7853981633974483;
    if (any(wide)) {
      for (int l = 0; l < W; ++l) {
        if (!wide[l]) continue;
        sinc[l] = std::sin(h[l]) / h[l];
        c[l] = std::cos(h[l]);
      }
    }
    const real k = 0.5 * sinc, x = k * w0, y = k * w1, zq = k * w2;
    const real xx = x * x, yy = y * y, zz = zq * zq, xy = x * y, xz = x * zq, yz = y * zq, cx = c * x, cy = c * y,
               cz = c * zq;
    const real E[9] = {1.0 - 2.0 * (yy + zz), 2.0 * (xy - cz),       2.0 * (xz + cy),
                       2.0 * (xy + cz),       1.0 - 2.0 * (xx + zz), 2.0 * (yz - cx),
                       2.0 * (xz - cy),       2.0 * (yz + cx),       1.0 - 2.0 * (xx + yy)};
    real dz[3] = {splat(0.0), splat(0.0), splat(0.0)};
    if (predicts(p))
      for (int r = 0; r < 3; ++r)
        dz[r] = ((((p.P[6 * r] * z[0] + p.P[6 * r + 1] * z[1]) + p.P[6 * r + 2] * z[2]) + p.P[6 * r + 3] * z[3]) +
                 p.P[6 * r + 4] * z[4]) + p.P[6 * r + 5] * z[5];
    real R[9], Rt[9], t[3], tm[3], d[3], dm[3];
    for (int r = 0; r < 3; ++r) {
      for (int q = 0; q < 3; ++q) {
        R[3 * r + q] = (E[3 * r] * p.R0[q] + E[3 * r + 1] * p.R0[3 + q]) + E[3 * r + 2] * p.R0[6 + q];
        Rt[3 * r + q] = (E[r] * p.R0[q] + E[3 + r] * p.R0[3 + q]) + E[6 + r] * p.R0[6 + q];
      }
      const real v = p.translation * z[r];
      t[r] = p.t0[r] + v;
      tm[r] = p.t0[r] - v;
      d[r] = first_direction(p, r, -(p.n0[r] + dz[r]));
      dm[r] = first_direction(p, r, -(p.n0[r] - dz[r]));
    }
    for (int e = 0; e < 9; ++e) put(even.R[e], R[e], lanes);
    for (int e = 0; e < 3; ++e) put(even.t[e], t[e], lanes), put(even.direction[e], d[e], lanes);
    for (int e = 0; e < 6; ++e) put(even.z[e], z[e], lanes);
    if (odd_lanes == 0) return;
    for (int e = 0; e < 9; ++e) put(odd.R[e], Rt[e], odd_lanes);
    for (int e = 0; e < 3; ++e) put(odd.t[e], tm[e], odd_lanes), put(odd.direction[e], dm[e], odd_lanes);
    for (int e = 0; e < 6; ++e) put(odd.z[e], -z[e], odd_lanes);
  }
#pragma GCC diagnostic pop

  typedef double v2 __attribute__((vector_size(16)));
  /// Lanes 2h, 2h + 1 of v (h = H, H + 1, .. while 2h < n) to dst + h stride: two lanes per pair (M = 4), each
  /// pair's lanes one 16-byte store at its own samples (a lane extraction straight to memory).
  template <int H = 0>
  __attribute__((always_inline)) static void put_pairs(double* dst, std::size_t stride, const real& v, int n) {
    if constexpr (2 * H < W) {
      if (2 * H >= n) return;
      const v2 half = __builtin_shufflevector(v, v, 2 * H, 2 * H + 1);
      std::memcpy(dst + H * stride, &half, sizeof half);
      put_pairs<H + 1>(dst, stride, v, n);
    }
  }

  /// Samples of antithetic pairs a0 .. a0 + count - 1 of each of the `pairs` plans: plan q's pair a0 + e goes to
  /// index q stride + e of `even`, its antithetic copy to the same index of `odd` (with one plan, odd's arrays may
  /// be null when count == 1 and the copy is not wanted: `odd_count` copies are written, count or count - 1; with
  /// several plans every pair has its copy, odd_count == count). Several plans fill the registers that one pair's
  /// count < W antithetic pairs would leave partly empty (M = 4: 2 of AVX2's 4 lanes, 2 of AVX-512's 8): the draws
  /// and poses of a register cost the same whatever its lanes hold.
  static void run(const SamplePlan* const* plans, std::size_t pairs, std::size_t stride, std::uint64_t a0,
                  std::size_t count, std::size_t odd_count, const SampleArrays& even, const SampleArrays& odd) {
    const std::size_t total = pairs * count, odd_total = pairs == 1 ? odd_count : total;
    for (std::size_t e0 = 0; e0 < total; e0 += W) {
      const int lanes = int(std::min<std::size_t>(W, total - e0));
      const int odd_lanes = int(std::min<std::size_t>(lanes, odd_total > e0 ? odd_total - e0 : 0));
      const std::size_t q0 = e0 / count, q1 = (e0 + std::size_t(lanes) - 1) / count;
      real z[6];
      if (q0 == q1) {  // one pair's samples (every register when count >= W, but for the last)
        const SamplePlan& p = *plans[q0];
        const std::size_t j0 = e0 - q0 * count, at = q0 * stride + j0;
        // p.key holds splitmix(splitmix(seed) ^ pair).
        u64 start{};
        for (int l = 0; l < W; ++l) start[l] = noise_start(p.key, a0 + j0 + std::uint64_t(l));
        sample_noise(start, z);
        const auto put = [at](double* dst, const real& v, int n) {
          if (n == W) std::memcpy(dst + at, &v, sizeof v);
          else for (int l = 0; l < n; ++l) dst[at + l] = v[l];
        };
        poses(p, z, put, lanes, odd_lanes, even, odd);
        continue;
      }
      // Lanes of pairs q0 .. q1: each lane's plan, key, index and place (padding lanes past `lanes` take the last
      // lane's plan and are not stored), then each field from the lanes' plans.
      const SamplePlan* lane[W];
      std::size_t at[W];
      u64 start{};
      {
        std::size_t q = q0, j = e0 - q0 * count;
        for (int l = 0; l < W; ++l) {
          lane[l] = plans[q];
          at[l] = q * stride + j;
          start[l] = noise_start(plans[q]->key, a0 + j);
          if (l + 1 < lanes && ++j == count) j = 0, ++q;
        }
      }
      sample_noise(start, z);
      LanePlan lp;
      const auto field = [&](auto get) {
        real v;
        for (int l = 0; l < W; ++l) v[l] = get(*lane[l]);
        return v;
      };
      for (int e = 0; e < 9; ++e) lp.R0[e] = field([e](const SamplePlan& p) { return p.R0[e]; });
      for (int e = 0; e < 3; ++e) {
        lp.t0[e] = field([e](const SamplePlan& p) { return p.t0[e]; });
        lp.n0[e] = field([e](const SamplePlan& p) { return p.n0[e]; });
        lp.first[e] = field([e](const SamplePlan& p) { return p.first[e]; });
      }
      for (int e = 0; e < 18; ++e) lp.P[e] = field([e](const SamplePlan& p) { return p.P[e]; });
      lp.translation = field([](const SamplePlan& p) { return p.translation; });
      lp.rotation = field([](const SamplePlan& p) { return p.rotation; });
      lp.predict = field([](const SamplePlan& p) { return p.predict ? 1.0 : 0.0; }) != 0.0;
      if (count == 2) {  // M = 4: every register starts a pair (e0 and W even), lanes 2h, 2h + 1 are pair q0 + h
        const std::size_t base = q0 * stride;
        const auto put = [base, stride](double* dst, const real& v, int n) { put_pairs(dst + base, stride, v, n); };
        poses(lp, z, put, lanes, odd_lanes, even, odd);
      } else {
        const auto put = [&at](double* dst, const real& v, int n) {
          for (int l = 0; l < n; ++l) dst[at[l]] = v[l];
        };
        poses(lp, z, put, lanes, odd_lanes, even, odd);
      }
    }
  }
};
