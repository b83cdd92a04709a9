// The wide traversal compiled for three instruction sets (the loop is ray_wide_traverse.inl) and the ray setup.
#include "ray_wide_traverse.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>

// The vector types cross no call boundary between instruction sets (each set's functions call only their own).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol {

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw")
namespace wide_avx512 {
#define BATCHCOL_WIDE_VLANES 16
#define BATCHCOL_WIDE_CMP(a, b, op) std::uint32_t(_mm512_cmp_ps_mask(__m512(a), __m512(b), op))
#define BATCHCOL_WIDE_LE(a, b) BATCHCOL_WIDE_CMP(a, b, _CMP_LE_OQ)
#define BATCHCOL_WIDE_ILT(a, b) std::uint32_t(_mm512_cmplt_epi32_mask(__m512i(a), __m512i(b)))
#define BATCHCOL_WIDE_LE8(a, b) std::uint32_t(_mm256_cmp_ps_mask(__m256(a), __m256(b), _CMP_LE_OQ))
#include "ray_wide_traverse.inl"
#include "ray_wide_packet.inl"
#undef BATCHCOL_WIDE_VLANES
#undef BATCHCOL_WIDE_LE
#undef BATCHCOL_WIDE_ILT
#undef BATCHCOL_WIDE_LE8
#undef BATCHCOL_WIDE_CMP
}  // namespace wide_avx512
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2")
namespace wide_avx2 {
#define BATCHCOL_WIDE_CMP(a, b, op) std::uint32_t(_mm256_movemask_ps(_mm256_cmp_ps(__m256(a), __m256(b), op)))
#define BATCHCOL_WIDE_VLANES 8
#define BATCHCOL_WIDE_LE(a, b) BATCHCOL_WIDE_CMP(a, b, _CMP_LE_OQ)
#define BATCHCOL_WIDE_ILT(a, b) \
  std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(__m256i(b), __m256i(a)))))
#define BATCHCOL_WIDE_LE8(a, b) BATCHCOL_WIDE_LE(a, b)
#include "ray_wide_traverse.inl"
#include "ray_wide_packet.inl"
#undef BATCHCOL_WIDE_VLANES
#undef BATCHCOL_WIDE_LE
#undef BATCHCOL_WIDE_ILT
#undef BATCHCOL_WIDE_LE8
#undef BATCHCOL_WIDE_CMP
#define BATCHCOL_SETUP_SQRT(v) D(_mm256_sqrt_pd(__m256d(v)))
#include "ray_wide_setup.inl"
#undef BATCHCOL_SETUP_SQRT
}  // namespace wide_avx2
#pragma GCC pop_options

namespace wide_baseline {
template <class Mask> inline std::uint32_t lane_bits(Mask m) {
  std::uint32_t bits = 0;
  for (int l = 0; l < 8; ++l) bits |= (m[l] != 0 ? 1u : 0u) << l;
  return bits;
}
#define BATCHCOL_WIDE_VLANES 8
#define BATCHCOL_WIDE_LE(a, b) lane_bits((a) <= (b))
#define BATCHCOL_WIDE_ILT(a, b) lane_bits((a) < (b))
#define BATCHCOL_WIDE_LE8(a, b) lane_bits((a) <= (b))
#include "ray_wide_traverse.inl"
#include "ray_wide_packet.inl"
#undef BATCHCOL_WIDE_VLANES
#undef BATCHCOL_WIDE_LE
#undef BATCHCOL_WIDE_ILT
#undef BATCHCOL_WIDE_LE8
template <class V> inline V sqrt_lanes(V v) {
  for (int l = 0; l < 4; ++l) v[l] = __builtin_sqrt(v[l]);
  return v;
}
#define BATCHCOL_SETUP_SQRT(v) sqrt_lanes(v)
#include "ray_wide_setup.inl"
#undef BATCHCOL_SETUP_SQRT
}  // namespace wide_baseline

namespace {

bool in_range(double x) { return x == 0.0 || (std::fabs(x) >= 0x1p-60 && std::fabs(x) <= 0x1p60); }

// The next float above / below a finite f (libm's nextafterf costs ~50 instructions; this is the per-ray setup).
float next_up(float f) {
  if (f == 0.0f) return 0x1p-149f;
  std::uint32_t u;
  __builtin_memcpy(&u, &f, sizeof u);
  u = f > 0.0f ? u + 1 : u - 1;
  __builtin_memcpy(&f, &u, sizeof u);
  return f;
}

float round_up(double x) {
  const float f = static_cast<float>(x);
  return double(f) < x ? next_up(f) : f;  // double(f) < x: f is finite (or -inf, not reached: |x| <= 2^60 here)
}

float round_down(double x) { return -round_up(-x); }

}  // namespace

bool wide_ray_supported(const double o[3], const double d[3]) {
  for (int k = 0; k < 3; ++k)
    if (!(std::fabs(o[k]) <= 0x1p60) || !in_range(d[k])) return false;
  return true;
}

WideRay make_wide_ray(const double o[3], const double d[3]) {
  WideRay r;
  r.octant = 0;
  for (int k = 0; k < 3; ++k) {
    const bool negative = std::signbit(d[k]);  // -0 counts as negative: 1 / -0 = -inf pairs with the hi plane
    r.inv[k] = static_cast<float>(1.0 / d[k]);
    r.octant |= negative ? 1u << k : 0u;
    r.o_near[k] = negative ? round_down(o[k]) : round_up(o[k]);
    r.o_far[k] = negative ? round_up(o[k]) : round_down(o[k]);
  }
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  double o_length = 0.0;
  for (int k = 0; k < 3; ++k) {
    r.ball_o[k] = static_cast<float>(o[k]);
    r.ball_d[k] = static_cast<float>(d[k] / len);
    o_length += std::fabs(o[k]);
  }
  r.ball_margin = round_up(double(kBallMargin) * o_length);
  return r;
}

void make_leaf_ball(const double c[3], double bound, float out[4]) {
  double length = 0.0;
  for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(c[k]), length += std::fabs(c[k]);
  const double radius = bound * (1.0 + double(kBallMargin)) + double(kBallMargin) * length;
  out[3] = bound > 0.0 && std::isfinite(radius) && radius < 0x1p100 ? std::max(round_up(radius), 0x1p-60f) : INFINITY;
}

float wide_limit_round_up(double x) { return round_up(x); }

WideTraverse wide_traverse_for(int isa) {
  switch (isa) {
    case 0: return &wide_baseline::traverse;
    case 1: return __builtin_cpu_supports("avx2") ? &wide_avx2::traverse : nullptr;
    case 2:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                     __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw")
                 ? &wide_avx512::traverse
                 : nullptr;
    default: return nullptr;
  }
}

WidePacketTraverse wide_packet_traverse_for(int isa) {
  switch (isa) {
    case 0: return &wide_baseline::traverse_packets;
    case 1: return wide_traverse_for(1) ? &wide_avx2::traverse_packets : nullptr;
    case 2: return wide_traverse_for(2) ? &wide_avx512::traverse_packets : nullptr;
    default: return nullptr;
  }
}

WidePacketTraverse select_wide_packet_traverse(int isa) {
  for (; isa > 0; --isa)
    if (WidePacketTraverse f = wide_packet_traverse_for(isa)) return f;
  return wide_packet_traverse_for(0);
}

WideRaySetup wide_ray_setup_for(int isa) {
  switch (isa) {
    case 0: return &wide_baseline::setup_rays;
    case 1: return wide_traverse_for(1) ? &wide_avx2::setup_rays : nullptr;
    // No AVX-512 build: 8 doubles would fill zmm registers, and 512-bit divisions and square roots can lower the
    // core's clock for everything after them (the traversal keeps to 256-bit registers for the same reason).
    default: return nullptr;
  }
}

WideRaySetup select_wide_ray_setup(int isa) {
  for (isa = std::min(isa, 1); isa > 0; --isa)
    if (WideRaySetup f = wide_ray_setup_for(isa)) return f;
  return wide_ray_setup_for(0);
}

WideRaySetup select_wide_ray_setup() { return select_wide_ray_setup(2); }

WideRecordSetup wide_record_setup_for(int isa) {
  switch (isa) {
    case 0: return &wide_baseline::setup_records;
    case 1: return wide_traverse_for(1) ? &wide_avx2::setup_records : nullptr;
    default: return nullptr;  // no AVX-512 build (wide_ray_setup_for())
  }
}

WideRecordSetup select_wide_record_setup(int isa) {
  for (isa = std::min(isa, 1); isa > 0; --isa)
    if (WideRecordSetup f = wide_record_setup_for(isa)) return f;
  return wide_record_setup_for(0);
}

WideTraverse select_wide_traverse(int isa) {
  for (; isa > 0; --isa)
    if (WideTraverse f = wide_traverse_for(isa)) return f;
  return wide_traverse_for(0);
}

WideTraverse select_wide_traverse() { return select_wide_traverse(2); }

}  // namespace batchcol
