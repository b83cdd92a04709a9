// The ordered cast's sort key one ray at a time, written as the key's definition (engine/src/ray_order_keys.hpp): the
// reference the production lanes (ray_order_keys()) are tested against. Production computes keys only in lanes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "batchcol/rays.hpp"
#include "engine/src/ray_order_keys.hpp"

namespace batchcol::testing {

/// The key of ray i: kRayOrderMissKey for an invalid ray or one that misses the box; else the 30-bit Morton code of
/// the entry point (the origin when inside) and the unit direction, 5 bits each, bits interleaved one at a time.
std::uint32_t ray_order_key_reference(const RayBatch& rays, std::size_t i, const detail::RayOrderBox& box);

}  // namespace batchcol::testing
