// The ordered cast's Morton key (ray_order_keys.hpp) in lanes; the one-ray reference is the tests'
// (tests/support/ray_order_key_reference.hpp).
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

void ray_order_keys(const RayBatch& rays, std::size_t begin, std::size_t n, const RayOrderBox& box, std::uint32_t* keys,
                    int isa) {
  static const bool avx2 = __builtin_cpu_supports("avx2") != 0;
  if (isa >= 1 && avx2)
    keys_avx2::keys(rays, begin, n, box, keys);
  else
    keys_baseline::keys(rays, begin, n, box, keys);
}

}  // namespace batchcol::detail
