// setup_rays(), the WideRaySetup of ray_wide_traverse.hpp: the per-ray setup of up to 8 rays at once, included once per instruction
// set next to the traversal. Each lane runs the IEEE operations of the scalar ray_is_valid(), wide_ray_supported()
// and make_wide_ray() in the same order (no fused multiply-adds: -ffp-contract=off), so every field is bitwise the
// scalar one on every instruction set; the data-dependent choices (rounding up or down, the sign's plane) are masks.
// Expects BATCHCOL_SETUP_SQRT(v): the lane-wise IEEE square root of a D.

namespace {

typedef double D __attribute__((vector_size(64)));
typedef std::int64_t L __attribute__((vector_size(64)));
typedef std::int32_t I8 __attribute__((vector_size(32)));
typedef float F8 __attribute__((vector_size(32)));
typedef unsigned U8 __attribute__((vector_size(32)));

inline D splat_d(double x) { return D{x, x, x, x, x, x, x, x}; }
inline D abs_d(D x) { return (D)((L)x & std::int64_t(0x7fffffffffffffff)); }  // clears the sign bit

// The smallest float >= x lane by lane (the scalar round_up()): rounded to nearest, then one step up where that
// fell below x (+1 on the bits of a positive float or +0, -1 on those of a negative one).
inline U8 round_up_bits(D x) {
  const F8 f = __builtin_convertvector(x, F8);
  const U8 below = (U8)__builtin_convertvector(__builtin_convertvector(f, D) < x, I8);
  const U8 u = (U8)f;
  return u + (below & (1u | (0u - (u >> 31))));
}

}  // namespace

void setup_rays(const WideRayInput& in, std::size_t begin, std::size_t n, WideRay* out, std::uint8_t* status) {
  // Lanes beyond n get a harmless ray (origin 0, direction 1, t_max 0) and are not written out.
  D o[3], d[3], t_max;
  for (int k = 0; k < 3; ++k) o[k] = splat_d(0.0), d[k] = splat_d(1.0);
  t_max = splat_d(0.0);
  for (std::size_t l = 0; l < n; ++l) {
    for (int k = 0; k < 3; ++k) o[k][l] = in.o[k][begin + l], d[k][l] = in.d[k][begin + l];
    t_max[l] = in.t_max[begin + l];
  }
  // ray_is_valid(): finite origin and direction, |d|^2 > 0, t_max >= 0 (NaN fails every comparison).
  const D huge = splat_d(0x1.fffffffffffffp+1023);
  L valid = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) > splat_d(0.0);
  valid &= t_max >= splat_d(0.0);
  // wide_ray_supported(): |o| <= 2^60, each d component 0 or of magnitude in [2^-60, 2^60].
  L supported = valid;
  for (int k = 0; k < 3; ++k) {
    const D ao = abs_d(o[k]), ad = abs_d(d[k]);
    valid &= (ao <= huge) & (ad <= huge);
    supported &= (ao <= splat_d(0x1p60)) & ((d[k] == splat_d(0.0)) | ((ad >= splat_d(0x1p-60)) & (ad <= splat_d(0x1p60))));
  }
  supported &= valid;
  // make_wide_ray().
  U8 inv[3], o_near[3], o_far[3], ball_o[3], ball_d[3];
  L negative[3];
  const D len = BATCHCOL_SETUP_SQRT(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  D o_length = splat_d(0.0);
  for (int k = 0; k < 3; ++k) {
    negative[k] = (L)d[k] < 0;  // the sign bit, -0 included
    const U8 neg32 = (U8)__builtin_convertvector(negative[k], I8);
    inv[k] = (U8)__builtin_convertvector(splat_d(1.0) / d[k], F8);
    const U8 up = round_up_bits(o[k]), down = round_up_bits(-o[k]) ^ 0x80000000u;  // round_down(x) = -round_up(-x)
    o_near[k] = (down & neg32) | (up & ~neg32);
    o_far[k] = (up & neg32) | (down & ~neg32);
    ball_o[k] = (U8)__builtin_convertvector(o[k], F8);
    ball_d[k] = (U8)__builtin_convertvector(d[k] / len, F8);
    o_length += abs_d(o[k]);
  }
  const U8 margin = round_up_bits(splat_d(double(kBallMargin)) * o_length);
  constexpr std::uint32_t lo[3] = {offsetof(WideNode, lo_x), offsetof(WideNode, lo_y), offsetof(WideNode, lo_z)};
  constexpr std::uint32_t hi[3] = {offsetof(WideNode, hi_x), offsetof(WideNode, hi_y), offsetof(WideNode, hi_z)};
  for (std::size_t l = 0; l < n; ++l) {
    status[l] = supported[l] ? kWideRaySupported : valid[l] ? kWideRayBinary : kWideRayInvalid;
    if (!supported[l]) continue;
    WideRay& r = out[l];
    for (int k = 0; k < 3; ++k) {
      __builtin_memcpy(&r.inv[k], &inv[k][l], 4);
      __builtin_memcpy(&r.o_near[k], &o_near[k][l], 4);
      __builtin_memcpy(&r.o_far[k], &o_far[k][l], 4);
      __builtin_memcpy(&r.ball_o[k], &ball_o[k][l], 4);
      __builtin_memcpy(&r.ball_d[k], &ball_d[k][l], 4);
      r.near_offset[k] = negative[k][l] ? hi[k] : lo[k];
      r.far_offset[k] = negative[k][l] ? lo[k] : hi[k];
    }
    __builtin_memcpy(&r.ball_margin, &margin[l], 4);
    r.balls = nullptr;
    r.prefetch = false;
  }
}
