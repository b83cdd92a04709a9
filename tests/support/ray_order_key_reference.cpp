// The scalar sort key (ray_order_key_reference.hpp). The bit spread is the plain loop, not the production lanes'
// multiply-and-mask, so the test also checks that trick; the arithmetic is the key's definition in IEEE double
// (the tree compiles with -ffp-contract=off, so no fused operations change its bits).
#include "ray_order_key_reference.hpp"

#include <algorithm>
#include <cmath>

#include "engine/src/rays_common.hpp"

namespace batchcol::testing {

namespace {

// Bit b of the low 5 bits of v moved to bit 6 b.
std::uint32_t spread_bits6(std::uint32_t v) {
  std::uint32_t t = 0;
  for (int b = 0; b < 5; ++b) t |= ((v >> b) & 1u) << (6 * b);
  return t;
}

}  // namespace

std::uint32_t ray_order_key_reference(const RayBatch& rays, std::size_t i, const detail::RayOrderBox& box) {
  if (!detail::ray_is_valid(rays, i)) return detail::kRayOrderMissKey;
  const double o[3] = {rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]};
  const double d[3] = {rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]};
  double t0 = 0.0, t1 = rays.t_max[i];
  for (int k = 0; k < 3; ++k) {
    const double inv = 1.0 / d[k], a = (box.lo[k] - o[k]) * inv, b = (box.hi[k] - o[k]) * inv;
    // NaN (an origin on a plane of a flat axis, or 0 * inf) is dropped by std::min / std::max's argument order.
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
  }
  if (!(t0 <= t1)) return detail::kRayOrderMissKey;
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const auto q = [](double x) { return static_cast<std::uint32_t>(std::min(31.0, std::max(0.0, x))); };
  std::uint32_t code = 0;
  for (int k = 0; k < 3; ++k) {
    code |= spread_bits6(q((o[k] + t0 * d[k] - box.lo[k]) * box.scale[k])) << (5 - k);
    code |= spread_bits6(q((d[k] / len + 1.0) * 16.0)) << (2 - k);
  }
  return code;
}

}  // namespace batchcol::testing
