// The sort key of the ordered ray cast (ray_scene_cast.cpp, RayOrder): rays that enter the scene near each other in
// similar directions get near keys, so that the nodes one ray loads are still in cache for the next. A 30-bit Morton
// code over 6 dimensions, 5 bits each: where the ray enters the scene's box (its origin when inside) and its unit
// direction; rays that miss the box, and invalid rays (detail::ray_is_valid() false), get kRayOrderMissKey (they cost
// little and are cast last). Only the order of work depends on it: each ray's answer depends on that ray alone.
#pragma once

#include <cstddef>
#include <cstdint>

#include "batchcol/rays.hpp"
#include "ray_wide_bvh.hpp"

namespace batchcol::detail {

constexpr std::uint32_t kRayOrderMissKey = 0x3fffffffu;

/// The scene's box (the union of the wide root's child boxes) and 32 / its extent per axis (0 for a flat or infinite
/// one).
struct RayOrderBox {
  float lo[3], hi[3];
  double scale[3];
};
RayOrderBox ray_order_box(const WideNode& root);

/// keys[l] = the key of ray begin + l for l < n, 4 rays per vector (the key's IEEE operations lane by lane, the
/// data-dependent choices as masks; tests/support/ray_order_key_reference.hpp is the one-ray form they are tested
/// against): a scalar key cost ~229 instructions a ray (AVX2 callgrind, 10k hulls), mostly its divisions and branches
/// on random data. isa (ray_isa_index(): 0 baseline, >= 1 AVX2 when the
/// processor has it) picks the lanes' instruction set; every set gives the same bits.
void ray_order_keys(const RayBatch& rays, std::size_t begin, std::size_t n, const RayOrderBox& box, std::uint32_t* keys,
                    int isa);

}  // namespace batchcol::detail
