// See ray_convex_planes.hpp. The entry is max over faces turned against the ray (denom < 0) of t_i = dist_i / denom_i,
// the exit min over the others. The loop (ray_convex_planes.inl) compares fractions instead of dividing: with the
// lane's best N / D,
//   t_i > N / D  <=>  dist_i D > N denom_i   (both denominators < 0, so their product is > 0),
//   t_i < X / Y  <=>  dist_i Y < X denom_i   (both > 0),
// two multiplies where a division costs 4-16 times more; -inf and +inf start as 1 / -0 and 1 / +0, which the
// inequalities above replace by the first face of each kind. Only the 8 lane winners are divided at the end, so the
// reported t is exactly dist_f / denom_f of the chosen face (two faces whose t differ by a rounding may swap).
// The loop uses GCC vector extensions with 8 lanes whatever the instruction set (one zmm, two ymm or four xmm
// registers per value), compiled three times below and picked per call (select_clip_planes(): the caller's cap on
// the instruction set, RayOptions::isa, and the processor's features).
#include "kernels/rays/ray_convex_planes.hpp"

#include <limits>

// The vector types cross no call boundary between instruction sets (each set's functions call only their own).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::kernels::rays {

#define BATCHCOL_CLIP_TYPES(SCALAR, BYTES, MASK)                                  \
  using T = SCALAR;                                                               \
  typedef SCALAR V __attribute__((vector_size(BYTES)));                           \
  typedef MASK M __attribute__((vector_size(BYTES)));

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw")
namespace clip_avx512::d {
BATCHCOL_CLIP_TYPES(double, 64, long long)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_avx512::d
namespace clip_avx512::f {
BATCHCOL_CLIP_TYPES(float, 32, int)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_avx512::f
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2")
namespace clip_avx2::d {
BATCHCOL_CLIP_TYPES(double, 64, long long)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_avx2::d
namespace clip_avx2::f {
BATCHCOL_CLIP_TYPES(float, 32, int)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_avx2::f
#pragma GCC pop_options

namespace clip_baseline::d {
BATCHCOL_CLIP_TYPES(double, 64, long long)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_baseline::d
namespace clip_baseline::f {
BATCHCOL_CLIP_TYPES(float, 32, int)
#include "kernels/rays/ray_convex_planes.inl"
}  // namespace clip_baseline::f

#undef BATCHCOL_CLIP_TYPES

ClipPlaneVariants clip_planes_for(int isa) {
  ClipPlaneVariants v;
  if (isa == 0) v.d = &clip_baseline::d::clip, v.f = &clip_baseline::f::clip;
  if (isa == 1 && __builtin_cpu_supports("avx2")) v.d = &clip_avx2::d::clip, v.f = &clip_avx2::f::clip;
  if (isa == 2 && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512bw"))
    v.d = &clip_avx512::d::clip, v.f = &clip_avx512::f::clip;
  return v;
}

ClipPlaneVariants select_clip_planes(int isa) {
  for (isa = isa > 2 ? 2 : isa; isa > 0; --isa)
    if (const ClipPlaneVariants v = clip_planes_for(isa); v.d != nullptr) return v;
  return clip_planes_for(0);
}

PlaneClip<double> clip_planes(const double* nx, const double* ny, const double* nz, const double* c, std::size_t n,
                              const double* o, const double* d, int isa) {
  return select_clip_planes(isa).d(nx, ny, nz, c, n, o, d);
}

PlaneClip<float> clip_planes(const float* nx, const float* ny, const float* nz, const float* c, std::size_t n,
                             const float* o, const float* d, int isa) {
  return select_clip_planes(isa).f(nx, ny, nz, c, n, o, d);
}

}  // namespace batchcol::kernels::rays
