// Order-preserving map from float to uint32, for radix sorting float keys (Terdiman, "Radix sort revisited", 2000;
// Herf, "Radix tricks", 2001).
//
// IEEE-754 floats of one sign are ordered like their bit patterns; negative floats are ordered backwards. Flipping
// every bit of a negative float and only the sign bit of a non-negative one gives unsigned integers ordered exactly
// like the floats: key(a) < key(b) <=> a < b for all non-NaN a, b -- except that -0 would sort before +0 although
// they compare equal, so -0 is canonicalised to +0 first. NaN never reaches this function (validate_aabbs rejects it).
#pragma once

#include <cstdint>
#include <cstring>

namespace batchcol::broadphase {

inline std::uint32_t sortable_key(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 -> +0 so that equal floats get equal keys (inclusive touching at 0 stays exact)
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

inline float key_to_float(std::uint32_t k) {
  const std::uint32_t u = (k & 0x80000000u) ? (k & 0x7fffffffu) : ~k;
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

}  // namespace batchcol::broadphase
