#include "derivative_smoothed1.hpp"

#include <immintrin.h>  // the lanes' square roots and lane tests (SSE2 here; AVX2 under its target pragma)

// 32-byte vectors in the AVX2 block: internal, inlined, no ABI crossing.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::detail {

namespace smoothed1_base {
namespace {
using V = double __attribute__((vector_size(16)));
using M = long long __attribute__((vector_size(16)));
inline __attribute__((always_inline)) V sqrt_lanes(V x) { return (V)_mm_sqrt_pd((__m128d)x); }
inline __attribute__((always_inline)) bool any_lane(M m) { return _mm_movemask_pd((__m128d)m) != 0; }
inline __attribute__((always_inline)) V blend_lanes(M m, V a, V b) { return (V)((m & (M)a) | (~m & (M)b)); }
}  // namespace
#include "derivative_smoothed1_lanes.inl"
}  // namespace smoothed1_base

#pragma GCC push_options
#pragma GCC target("avx2")
namespace smoothed1_avx2 {
namespace {
using V = double __attribute__((vector_size(32)));
using M = long long __attribute__((vector_size(32)));
inline __attribute__((always_inline)) V sqrt_lanes(V x) { return (V)_mm256_sqrt_pd((__m256d)x); }
inline __attribute__((always_inline)) bool any_lane(M m) { return _mm256_movemask_pd((__m256d)m) != 0; }
inline __attribute__((always_inline)) V blend_lanes(M m, V a, V b) {
  return (V)_mm256_blendv_pd((__m256d)b, (__m256d)a, (__m256d)m);  // a compare's lanes are all ones or zero
}
}  // namespace
#include "derivative_smoothed1_lanes.inl"
// Not inlined into the baseline caller (a target mismatch).
__attribute__((noinline)) void finish_block(const Smoothed1Lanes& in, SmoothLanes& lanes) {
  for (std::size_t l = 0; l < Smoothed1Lanes::kLanes; l += 4)
    if ((in.pending >> l) & 0xFu) finish_lanes<V, M>(in, l, lanes);
}
}  // namespace smoothed1_avx2
#pragma GCC pop_options

void Smoothed1Lanes::set(std::size_t l, const Eigen::Matrix3d& S_a, const Eigen::Matrix3d& S_b,
                         const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const auto side = [&](int s, const Eigen::Matrix3d& Sm, const Eigen::Matrix3d& Rm) {
    S[s][0][l] = Sm(0, 0), S[s][1][l] = Sm(1, 1), S[s][2][l] = Sm(2, 2);
    S[s][3][l] = Sm(0, 1), S[s][4][l] = Sm(0, 2), S[s][5][l] = Sm(1, 2);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R[s][3 * i + j][l] = Rm(i, j);
  };
  side(0, S_a, R_a);
  side(1, S_b, R_b);
  pending |= 1u << l;
}

void Smoothed1Lanes::finish(SmoothLanes& lanes, InstructionSet isa) const {
  if (pending == 0) return;
  if (isa == InstructionSet::avx2 || isa == InstructionSet::avx512) return smoothed1_avx2::finish_block(*this, lanes);
  for (std::size_t l = 0; l < kLanes; l += 2)
    if ((pending >> l) & 0x3u) smoothed1_base::finish_lanes<smoothed1_base::V, smoothed1_base::M>(*this, l, lanes);
}

}  // namespace batchcol::detail
