// The lanes of ray_order_keys() (ray_order_keys.hpp), included once per instruction set inside a `#pragma GCC target`
// region and a namespace of its own (ray_order_keys.cpp). Expects BATCHCOL_KEYS_SQRT(v): the lane-wise IEEE square root
// of a D. No fused multiply-adds (-ffp-contract=off): every set gives ray_order_key()'s bits.

namespace {

// Four lanes, one 256-bit register of doubles on AVX2. On the baseline (SSE2) GCC lowers the 64-bit masks' selects to
// scalar compares and branches (261 instructions a ray, callgrind, against 229 for the scalar key): the baseline build
// is the fallback, not the fast path.
typedef double D __attribute__((vector_size(32)));
typedef std::int64_t L __attribute__((vector_size(32)));
typedef std::int32_t I4 __attribute__((vector_size(16)));
typedef std::uint32_t U4 __attribute__((vector_size(16)));

inline D splat(double x) { return D{x, x, x, x}; }
inline D abs_d(D x) { return (D)((L)x & std::int64_t(0x7fffffffffffffff)); }

// ray_order_key()'s quantisation q(): std::min(31.0, std::max(0.0, x)) truncated (NaN -> 0), then spread.
inline U4 quantise_spread(D x) {
  const D y = splat(0.0) < x ? x : splat(0.0);
  const D z = y < splat(31.0) ? y : splat(31.0);
  return ((U4) __builtin_convertvector(z, I4) * kSpreadCopies) & kSpreadBits;
}

inline I4 narrow(L mask) { return __builtin_convertvector(mask, I4); }

// Lanes [0, 4) of rows (o x, y, z, d x, y, z, t_max).
U4 keys4(const double (&in)[7][4], const RayOrderBox& box) {
  D o[3], d[3], t_max;
  for (int k = 0; k < 3; ++k) __builtin_memcpy(&o[k], in[k], sizeof(D)), __builtin_memcpy(&d[k], in[3 + k], sizeof(D));
  __builtin_memcpy(&t_max, in[6], sizeof(D));
  // detail::ray_is_valid(): finite origin and direction, |d|^2 > 0, t_max >= 0 (NaN fails every comparison).
  const D huge = splat(0x1.fffffffffffffp+1023), dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  L ok = (dd > splat(0.0)) & (t_max >= splat(0.0));
  for (int k = 0; k < 3; ++k) ok &= (abs_d(o[k]) <= huge) & (abs_d(d[k]) <= huge);
  // The slab test against the scene's box, std::min / std::max as written in ray_order_key().
  D t0 = splat(0.0), t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    const D inv = splat(1.0) / d[k], a = (splat(double(box.lo[k])) - o[k]) * inv,
            b = (splat(double(box.hi[k])) - o[k]) * inv;
    const D lower = b < a ? b : a, upper = a < b ? b : a;
    t0 = t0 < lower ? lower : t0;
    t1 = upper < t1 ? upper : t1;
  }
  ok &= t0 <= t1;
  const D len = BATCHCOL_KEYS_SQRT(dd);
  U4 code = {0, 0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    code |= quantise_spread((o[k] + t0 * d[k] - splat(double(box.lo[k]))) * splat(box.scale[k])) << (5 - k);
    code |= quantise_spread((d[k] / len + splat(1.0)) * splat(16.0)) << (2 - k);
  }
  const U4 hit = (U4)narrow(ok);
  return (code & hit) | (kRayOrderMissKey & ~hit);
}

}  // namespace

void keys(const RayBatch& rays, std::size_t begin, std::size_t n, const RayOrderBox& box, std::uint32_t* keys) {
  const double* src[7] = {rays.origin.x.data(),    rays.origin.y.data(),    rays.origin.z.data(),
                          rays.direction.x.data(), rays.direction.y.data(), rays.direction.z.data(),
                          rays.t_max.data()};
  for (std::size_t b = 0; b < n; b += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - b);
    double rows[7][4];
    if (m == 4) {
      for (int r = 0; r < 7; ++r) __builtin_memcpy(rows[r], src[r] + begin + b, sizeof rows[r]);
    } else {  // a partial group pads with a harmless ray (origin 0, direction 1, t_max 0) that is not written out
      for (int l = 0; l < 4; ++l)
        for (int r = 0; r < 7; ++r)
          rows[r][l] = std::size_t(l) < m ? src[r][begin + b + l] : (r >= 3 && r < 6 ? 1.0 : 0.0);
    }
    const U4 k = keys4(rows, box);
    for (std::size_t l = 0; l < m; ++l) keys[b + l] = k[l];
  }
}
