// The ordered cast's Morton key (ray_order_keys.hpp), per ray and in lanes.
#include "ray_order_keys.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "rays_common.hpp"

// The vector types cross no call boundary between instruction sets (each set's functions call only their own).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::detail {

namespace {

// The low 5 bits of v spread to every sixth bit (bits 0, 6, ..., 24): the product places copies of v at bits 0, 5, 10,
// 15 and 20 (no carries: each copy is 5 bits wide), and copy b's bit b sits at bit 6 b, which the mask keeps.
constexpr std::uint32_t kSpreadCopies = 0x108421u, kSpreadBits = 0x1041041u;
constexpr std::uint32_t spread6(std::uint32_t v) { return (v * kSpreadCopies) & kSpreadBits; }
constexpr bool spread6_is_the_bit_spread() {
  for (std::uint32_t v = 0; v < 32; ++v) {
    std::uint32_t t = 0;
    for (int b = 0; b < 5; ++b) t |= ((v >> b) & 1u) << (6 * b);
    if (spread6(v) != t) return false;
  }
  return true;
}
static_assert(spread6_is_the_bit_spread(), "spread6");

}  // namespace

#pragma GCC push_options
#pragma GCC target("avx2")
namespace keys_avx2 {
#define BATCHCOL_KEYS_SQRT(v) D(_mm256_sqrt_pd(__m256d(v)))
#include "ray_order_keys.inl"
#undef BATCHCOL_KEYS_SQRT
}  // namespace keys_avx2
#pragma GCC pop_options

namespace keys_baseline {
template <class V>
inline V sqrt_lanes(V v) {
  for (int l = 0; l < 4; ++l) v[l] = __builtin_sqrt(v[l]);
  return v;
}
#define BATCHCOL_KEYS_SQRT(v) sqrt_lanes(v)
#include "ray_order_keys.inl"
#undef BATCHCOL_KEYS_SQRT
}  // namespace keys_baseline

RayOrderBox ray_order_box(const WideNode& root) {
  RayOrderBox box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, {}};
  const float* rl[3] = {root.lo_x, root.lo_y, root.lo_z};
  const float* rh[3] = {root.hi_x, root.hi_y, root.hi_z};
  for (int c = 0; c < kWideArity; ++c)
    if (root.child[c] != kWideEmpty)
      for (int k = 0; k < 3; ++k) box.lo[k] = std::min(box.lo[k], rl[k][c]), box.hi[k] = std::max(box.hi[k], rh[k][c]);
  for (int k = 0; k < 3; ++k) {
    const double extent = double(box.hi[k]) - double(box.lo[k]);
    box.scale[k] = extent > 0.0 && std::isfinite(extent) ? 32.0 / extent : 0.0;
  }
  return box;
}

std::uint32_t ray_order_key(const RayBatch& rays, std::size_t i, const RayOrderBox& box) {
  if (!ray_is_valid(rays, i)) return kRayOrderMissKey;
  const double o[3] = {rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]};
  const double d[3] = {rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]};
  double t0 = 0.0, t1 = rays.t_max[i];
  for (int k = 0; k < 3; ++k) {
    const double inv = 1.0 / d[k], a = (box.lo[k] - o[k]) * inv, b = (box.hi[k] - o[k]) * inv;
    t0 = std::max(t0, std::min(a, b));  // NaN (origin on a plane of a flat axis)
                                        // is dropped by min / max
    t1 = std::min(t1, std::max(a, b));
  }
  if (!(t0 <= t1)) return kRayOrderMissKey;
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const auto q = [](double x) { return static_cast<std::uint32_t>(std::min(31.0, std::max(0.0, x))); };
  std::uint32_t code = 0;
  for (int k = 0; k < 3; ++k) {
    code |= spread6(q((o[k] + t0 * d[k] - box.lo[k]) * box.scale[k])) << (5 - k);
    code |= spread6(q((d[k] / len + 1.0) * 16.0)) << (2 - k);
  }
  return code;
}

void ray_order_keys(const RayBatch& rays, std::size_t begin, std::size_t n, const RayOrderBox& box, std::uint32_t* keys,
                    int isa) {
  static const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  if (isa >= 1 && avx2)
    keys_avx2::keys(rays, begin, n, box, keys);
  else
    keys_baseline::keys(rays, begin, n, box, keys);
}

}  // namespace batchcol::detail
