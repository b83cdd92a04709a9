// A counter-based Gaussian generator: every (seed, pair, sample, stream) key starts its own SplitMix64 sequence
// (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014), so a sample's noise depends
// on its key only, never on which thread or batch chunk draws it. That is what makes the smoothed derivatives
// bitwise identical for any thread count; a shared engine would hand out numbers in scheduling order.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace batchcol::detail {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// log(u) for u in (0, 1] (uniform()'s range, whose smallest value 2^-53 is normal) without a libm call: u = 2^k m
/// with m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s) with s = (m - 1) / (m + 1), |s| <= 0.172, by its series to
/// s^23 (the next term is below 1e-17 of the sum). Within a few ulps of std::log; the same bits on every machine
/// (plain IEEE operations, no FMA contraction), which kernels/simd/wide_samples.inl repeats lane by lane.
inline double log_unit(double u) {
  std::uint64_t bits;
  std::memcpy(&bits, &u, sizeof bits);
  int k = static_cast<int>(bits >> 52) - 1023;
  bits = (bits & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull;
  double m;
  std::memcpy(&m, &bits, sizeof m);
  if (m > 1.4142135623730951) {
    m *= 0.5;
    ++k;
  }
  const double s = (m - 1.0) / (m + 1.0), z = s * s;
  // 1/23, 1/21, ..., 1/1 spelled out: a loop over 1.0 / n divided at run time unless fully unrolled.
  const double p = (((((((((((1.0 / 23.0) * z + 1.0 / 21.0) * z + 1.0 / 19.0) * z + 1.0 / 17.0) * z + 1.0 / 15.0) * z +
                          1.0 / 13.0) * z + 1.0 / 11.0) * z + 1.0 / 9.0) * z + 1.0 / 7.0) * z + 1.0 / 5.0) * z +
                    1.0 / 3.0) * z + 1.0;
  return k * 0.6931471805599453 + 2.0 * s * p;
}

/// sin(x) / x and cos(x) for |x| <= pi/4 by their Taylor series to x^16 (remainder below 5e-17).
inline void sinc_cos_small(double x, double& sinc, double& cos) {
  const double z = x * x;
  sinc = ((((((((-1.0 / 355687428096000.0) * z + 1.0 / 1307674368000.0) * z - 1.0 / 6227020800.0) * z +
               1.0 / 39916800.0) * z - 1.0 / 362880.0) * z + 1.0 / 5040.0) * z - 1.0 / 120.0) * z + 1.0 / 6.0);
  sinc = 1.0 - z * sinc;
  cos = (((((((1.0 / 20922789888000.0 * z - 1.0 / 87178291200.0) * z + 1.0 / 479001600.0) * z - 1.0 / 3628800.0) *
               z + 1.0 / 40320.0) * z - 1.0 / 720.0) * z + 1.0 / 24.0) * z - 0.5) * z + 1.0;
}

/// sin and cos of 2 pi u for u in [0, 1]: the quarter turn q nearest 4u is exact to remove (u - q/4 is exact), the
/// rest (|x| <= pi/4) goes through sinc_cos_small.
inline void sincos_turn(double u, double& sin, double& cos) {
  const int q = static_cast<int>(4.0 * u + 0.5);
  const double x = 6.283185307179586 * (u - 0.25 * q);
  double sx, cx;
  sinc_cos_small(x, sx, cx);
  sx *= x;
  switch (q & 3) {
    case 0: sin = sx, cos = cx; break;
    case 1: sin = cx, cos = -sx; break;
    case 2: sin = -sx, cos = -cx; break;
    default: sin = -cx, cos = sx; break;
  }
}

class CounterRng {
 public:
  // The key words are chained through the mixer (not XORed together), so keys differing in any word give
  // unrelated sequences.
  CounterRng(std::uint64_t seed, std::uint64_t pair, std::uint64_t sample, std::uint64_t stream)
      : state_(splitmix64(splitmix64(splitmix64(splitmix64(seed) ^ pair) ^ sample) ^ stream)) {}

  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return splitmix64(state_);
  }
  /// Uniform in (0, 1]: 53 random bits, shifted by one so log() below never sees 0.
  double uniform() { return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53; }
  /// Two independent standard normals (Box-Muller).
  void gaussian_pair(double& g0, double& g1) {
    const double radius = std::sqrt(-2.0 * log_unit(uniform()));
    double s, c;
    sincos_turn(uniform(), s, c);
    g0 = radius * c;
    g1 = radius * s;
  }

 private:
  std::uint64_t state_;
};

/// z in R^N, standard normal, for (seed, pair, sample, stream); N even.
template <int N> void gaussian_vector(std::uint64_t seed, std::uint64_t pair, std::uint64_t sample,
                                      std::uint64_t stream, double* z) {
  CounterRng rng(seed, pair, sample, stream);
  for (int k = 0; k < N; k += 2) rng.gaussian_pair(z[k], z[k + 1]);
}

/// log_unit() and sincos_turn() with shorter series for support_noise_pair(): log to s^11 (relative error below
/// z^6 / 13 = 5e-11 at |s| <= 0.172), sin to x^11 and cos to x^12 (below 1e-11 at |x| <= pi/4). Noise needs the
/// normal distribution, not the last bits of its deviates: 5e-11 is far below any sampling error.
inline double log_unit_short(double u) {
  std::uint64_t bits;
  std::memcpy(&bits, &u, sizeof bits);
  int k = static_cast<int>(bits >> 52) - 1023;
  bits = (bits & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull;
  double m;
  std::memcpy(&m, &bits, sizeof m);
  if (m > 1.4142135623730951) {
    m *= 0.5;
    ++k;
  }
  const double s = (m - 1.0) / (m + 1.0), z = s * s;
  const double p = (((((1.0 / 11.0) * z + 1.0 / 9.0) * z + 1.0 / 7.0) * z + 1.0 / 5.0) * z + 1.0 / 3.0) * z + 1.0;
  return k * 0.6931471805599453 + 2.0 * s * p;
}
inline void sincos_turn_short(double u, double& sin, double& cos) {
  const int q = static_cast<int>(4.0 * u + 0.5);
  const double x = 6.283185307179586 * (u - 0.25 * q), z = x * x;
  const double sx =
      x * (((((-1.0 / 39916800.0 * z + 1.0 / 362880.0) * z - 1.0 / 5040.0) * z + 1.0 / 120.0) * z - 1.0 / 6.0) * z +
           1.0);
  const double cx = ((((((1.0 / 479001600.0) * z - 1.0 / 3628800.0) * z + 1.0 / 40320.0) * z - 1.0 / 720.0) * z +
                      1.0 / 24.0) * z - 0.5) * z + 1.0;
  switch (q & 3) {
    case 0: sin = sx, cos = cx; break;
    case 1: sin = cx, cos = -sx; break;
    case 2: sin = -sx, cos = -cx; break;
    default: sin = -cx, cos = sx; break;
  }
}

/// smoothed1's support noise (engine/src/derivatives.cpp; kernels::simd::draw_support_noise() draws it W pairs per
/// register with these bits): normals 2j and 2j + 1 of a pair with key splitmix64(splitmix64(seed) ^ pair) are
/// one Box-Muller transform of the j-th output x of the SplitMix64 sequence started at the key, its high 32 bits
/// the radius' uniform (hi + 1) 2^-32 in (0, 1] and its low 32 bits the angle's lo 2^-32 in [0, 1). One 64-bit
/// mix per two normals where gaussian_vector<4> paid two mixes of key set-up per lane and one per uniform (with
/// AVX2's emulated 64-bit products, those mixes were most of the draw), and only the 3 normals a side uses per
/// draw instead of 4: issue 18's M = 4 budget. 32-bit uniforms cut the radius at sqrt(64 ln 2) = 6.66 (a
/// normal's two-sided tail beyond it has probability 3e-11) and quantise the angle to 2^-32 of a turn: far below
/// the estimator's sampling error at any M the API takes.
inline void support_noise_pair(std::uint64_t key, std::uint64_t j, double& g0, double& g1) {
  const std::uint64_t x = splitmix64(key + j * 0x9E3779B97F4A7C15ull);
  const double u_radius = (static_cast<double>(x >> 32) + 1.0) * 0x1.0p-32;
  const double u_angle = static_cast<double>(x & 0xFFFFFFFFull) * 0x1.0p-32;
  const double radius = std::sqrt(-2.0 * log_unit_short(u_radius));
  double s, c;
  sincos_turn_short(u_angle, s, c);
  g0 = radius * c;
  g1 = radius * s;
}

}  // namespace batchcol::detail
