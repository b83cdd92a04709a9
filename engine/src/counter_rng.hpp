// Counter-based Gaussian noise: every (seed, pair) key starts its own SplitMix64 sequence (Steele, Lea, Flood,
// "Fast splittable pseudorandom number generators", OOPSLA 2014) and a sample's draws are fixed outputs of it, so a
// sample's noise depends on its key and index only, never on which thread or batch chunk draws it. That is what makes the smoothed derivatives
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

/// support_noise_pair()'s float Box-Muller pieces, each a fixed sequence of IEEE float operations (the build has
/// -ffp-contract=off, so no FMA fuses them on any set) that kernels/simd/wide_samples.inl repeats lane by lane,
/// 2 W lanes a register: float halves the lanes' width, and every integer <-> float conversion here is a native
/// 32-bit one on AVX2 (64-bit lanes had none).
///
/// -2 log(u) for u = (h + 1) 2^-31 (h < 2^31): u = 2^k m with m in [sqrt(1/2), sqrt(2)) by integer steps on u's
/// bits (the bits minus sqrt(1/2)'s, shifted, are k), log m = 2 atanh(s), s = (m - 1) / (m + 1), |s| <= 0.1716,
/// by its series to s^9 (remainder below s^11 / 11 < 2e-9 of the sum; float rounding, ~1e-7, dominates).
/// Never negative: for k = 0, m < 1 and s < 0 exactly; for k < 0, |2 s p| <= log sqrt(2) < ln 2.
inline float minus_two_log_unit_f(std::uint32_t h) {
  const float u = (static_cast<float>(static_cast<std::int32_t>(h)) + 1.0f) * 0x1.0p-31f;
  std::int32_t bits;
  std::memcpy(&bits, &u, sizeof bits);
  const std::int32_t k = (bits - 0x3F3504F3) >> 23;  // arithmetic shift (C++20 defines it; GCC always has)
  bits -= static_cast<std::int32_t>(static_cast<std::uint32_t>(k) << 23);
  float m;
  std::memcpy(&m, &bits, sizeof m);
  const float s = (m - 1.0f) / (m + 1.0f), z = s * s;
  const float p = (((1.0f / 9.0f * z + 1.0f / 7.0f) * z + 1.0f / 5.0f) * z + 1.0f / 3.0f) * z + 1.0f;
  return static_cast<float>(k) * static_cast<float>(-2.0 * 0.6931471805599453) - (4.0f * s) * p;
}

/// sin and cos of the angle a 2^-32 turn: the nearest quarter turn q (the top 2 bits of a + 2^29) is removed in
/// integers, exactly, the rest r (a's low 30 bits as a signed number, |r| <= 2^29, x = 2 pi r 2^-32 with
/// |x| <= pi/4) goes through Taylor series to x^9 (sin, remainder below 2e-9) and x^8 (cos, below 3e-8), and the
/// quadrant is a swap and two sign flips.
inline void sincos_turn_f(std::uint32_t a, float& sin, float& cos) {
  const std::uint32_t q = (a + 0x20000000u) >> 30;
  const std::int32_t r = static_cast<std::int32_t>(a - (q << 30));
  const float x = static_cast<float>(r) * static_cast<float>(6.283185307179586 * 0x1.0p-32), z = x * x;
  const float sx = x * ((((1.0f / 362880.0f * z - 1.0f / 5040.0f) * z + 1.0f / 120.0f) * z - 1.0f / 6.0f) * z + 1.0f);
  const float cx = (((1.0f / 40320.0f * z - 1.0f / 720.0f) * z + 1.0f / 24.0f) * z - 0.5f) * z + 1.0f;
  const bool swap = (q & 1u) != 0;
  sin = swap ? cx : sx;
  cos = swap ? sx : cx;
  if (q & 2u) sin = -sin;              // q = 2, 3: sin(x + pi) = -sin x
  if ((q + 1u) & 2u) cos = -cos;       // q = 1, 2: cos(x + pi/2) = -sin x, cos(x + pi) = -cos x
}

/// smoothed1's support noise (engine/src/derivatives.cpp; kernels::simd::draw_support_noise() draws it 2 W
/// transforms per register with these bits): normals 2j and 2j + 1 of a pair with key splitmix64(splitmix64(seed)
/// ^ pair) are one Box-Muller transform of the j-th output x of the SplitMix64 sequence started at the key, its
/// high 32 bits h the radius' uniform ((h >> 1) + 1) 2^-31 in (0, 1] (rounded to float above 2^24: only near
/// u = 1, where log is flat) and its low 32 bits the angle in 2^-32 turns, in float (branch sm4; sm3 did the same
/// transform in double with series to 5e-11: other output bits since, the same distribution). One 64-bit mix per
/// two normals, and only the 3 normals a side uses per draw: issue 18's M = 4 budget. The 31-bit uniform cuts the
/// radius at sqrt(62 ln 2) = 6.56 (a normal pair's radius exceeds it with probability 2^-31 = 5e-10), the angle is
/// quantised to 2^-32 of a turn, and the float series and roundings are within ~1e-7 relative: far below the
/// estimator's sampling error at any M the API takes (tests/kernels/wide_samples_test.cpp checks the moments).
inline void support_noise_pair(std::uint64_t key, std::uint64_t j, double& g0, double& g1) {
  const std::uint64_t x = splitmix64(key + j * 0x9E3779B97F4A7C15ull);
  const float radius = std::sqrt(minus_two_log_unit_f(static_cast<std::uint32_t>(x >> 33)));
  float s, c;
  sincos_turn_f(static_cast<std::uint32_t>(x), s, c);
  g0 = static_cast<double>(radius * c);
  g1 = static_cast<double>(radius * s);
}

/// smoothed0's noise of antithetic pair k of a pair with key splitmix64(splitmix64(seed) ^ pair) (engine/src/
/// derivative_smoothed0.cpp; kernels::simd::build_samples() draws it W antithetic pairs a register with these
/// bits): z = (z_v, z_w) in R^6 are support_noise_pair()'s transforms 3k, 3k + 1, 3k + 2 of the key's sequence,
/// the same stream as smoothed1's draw k. Until branch dv2 smoothed0 drew gaussian_vector<6>(seed, pair, k, 0):
/// 8 64-bit mixes a draw (2 for the key set-up; AVX2 emulates their multiplies) and double log / sin / cos series
/// to 1e-17, against 3 mixes and float series here; other output bits since, the same distribution (radius cut at
/// 6.56 sigma, ~1e-7 relative roundings: support_noise_pair()'s note).
inline void sample_noise(std::uint64_t key, std::uint64_t k, double* z) {
  for (std::uint64_t t = 0; t < 3; ++t) support_noise_pair(key, 3 * k + t, z[2 * t], z[2 * t + 1]);
}

}  // namespace batchcol::detail
