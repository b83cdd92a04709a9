// setup_rays(), the WideRaySetup of ray_wide_traverse.hpp: the per-ray setup of up to 8 rays at once, included once per instruction
// set next to the traversal. Each lane runs the IEEE operations of the scalar ray_is_valid(), wide_ray_supported()
// and make_wide_ray() in the same order (no fused multiply-adds: -ffp-contract=off), so every field is bitwise the
// scalar one on every instruction set; the data-dependent choices (rounding up or down, the sign's plane) are masks.
// Expects BATCHCOL_SETUP_SQRT(v): the lane-wise IEEE square root of a D.

namespace {

// Four lanes per vector (one 256-bit register of doubles): GCC lowers wider vectors' double comparisons on AVX2 to
// scalar compares and branches, ~2700 instructions for 8 rays; 4-lane ones are single instructions.
typedef double D __attribute__((vector_size(32)));
typedef std::int64_t L __attribute__((vector_size(32)));
typedef float F4 __attribute__((vector_size(16)));
typedef std::uint32_t U4 __attribute__((vector_size(16)));
typedef std::int32_t I4 __attribute__((vector_size(16)));

inline D splat_d(double x) { return D{x, x, x, x}; }
inline D abs_d(D x) { return (D)((L)x & std::int64_t(0x7fffffffffffffff)); }  // clears the sign bit

// The smallest float >= x lane by lane (the scalar round_up()): rounded to nearest, then one step up where that
// fell below x (+1 on the bits of a positive float or +0, -1 on those of a negative one).
inline U4 round_up_bits(D x) {
  const F4 f = __builtin_convertvector(x, F4);
  const U4 below = (U4)__builtin_convertvector(__builtin_convertvector(f, D) < x, I4);
  const U4 u = (U4)f;
  return u + (below & (1u | (0u - (u >> 31))));
}

// Lanes [b, b + 4) of the group: the arrays below hold 8 lanes.
struct SetupLanes {
  float inv[3][8], near[3][8], far[3][8], ball_o[3][8], ball_d[3][8], margin[8];
  std::uint32_t near_off[3][8], far_off[3][8];
  std::int64_t supported[8], valid[8];
};

void setup4(const double (&in)[7][8], int b, SetupLanes& s) {
  D o[3], d[3], t_max;
  for (int k = 0; k < 3; ++k) __builtin_memcpy(&o[k], &in[k][b], sizeof(D)), __builtin_memcpy(&d[k], &in[3 + k][b], sizeof(D));
  __builtin_memcpy(&t_max, &in[6][b], sizeof(D));
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
  __builtin_memcpy(&s.supported[b], &supported, sizeof supported);
  __builtin_memcpy(&s.valid[b], &valid, sizeof valid);
  // make_wide_ray().
  constexpr std::uint32_t lo[3] = {offsetof(WideNode, lo_x), offsetof(WideNode, lo_y), offsetof(WideNode, lo_z)};
  constexpr std::uint32_t hi[3] = {offsetof(WideNode, hi_x), offsetof(WideNode, hi_y), offsetof(WideNode, hi_z)};
  const D len = BATCHCOL_SETUP_SQRT(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  D o_length = splat_d(0.0);
  for (int k = 0; k < 3; ++k) {
    const U4 neg = (U4)__builtin_convertvector((L)d[k] < 0, I4);  // the sign bit, -0 included
    const U4 inv = (U4)__builtin_convertvector(splat_d(1.0) / d[k], F4);
    const U4 up = round_up_bits(o[k]), down = round_up_bits(-o[k]) ^ 0x80000000u;  // round_down(x) = -round_up(-x)
    const U4 o_near = (down & neg) | (up & ~neg), o_far = (up & neg) | (down & ~neg);
    const U4 near_offset = (hi[k] & neg) | (lo[k] & ~neg), far_offset = (lo[k] & neg) | (hi[k] & ~neg);
    const F4 ball_o = __builtin_convertvector(o[k], F4), ball_d = __builtin_convertvector(d[k] / len, F4);
    __builtin_memcpy(&s.inv[k][b], &inv, sizeof inv);
    __builtin_memcpy(&s.near[k][b], &o_near, sizeof o_near);
    __builtin_memcpy(&s.far[k][b], &o_far, sizeof o_far);
    __builtin_memcpy(&s.near_off[k][b], &near_offset, sizeof near_offset);
    __builtin_memcpy(&s.far_off[k][b], &far_offset, sizeof far_offset);
    __builtin_memcpy(&s.ball_o[k][b], &ball_o, sizeof ball_o);
    __builtin_memcpy(&s.ball_d[k][b], &ball_d, sizeof ball_d);
    o_length += abs_d(o[k]);
  }
  const U4 margin = round_up_bits(splat_d(double(kBallMargin)) * o_length);
  __builtin_memcpy(&s.margin[b], &margin, sizeof margin);
}

}  // namespace

void setup_rays(const WideRayInput& in, std::size_t begin, std::size_t n, WideRay* out, std::uint8_t* status) {
  // The group's inputs as 7 rows of 8 lanes; a partial group pads its lanes with a harmless ray (origin 0,
  // direction 1, t_max 0) that is not written out.
  double rows[7][8];
  if (n == 8) {
    for (int k = 0; k < 3; ++k) {
      __builtin_memcpy(rows[k], in.o[k] + begin, sizeof rows[k]);
      __builtin_memcpy(rows[3 + k], in.d[k] + begin, sizeof rows[k]);
    }
    __builtin_memcpy(rows[6], in.t_max + begin, sizeof rows[6]);
  } else {
    for (int l = 0; l < 8; ++l)
      rows[0][l] = rows[1][l] = rows[2][l] = rows[6][l] = 0.0, rows[3][l] = rows[4][l] = rows[5][l] = 1.0;
    for (std::size_t l = 0; l < n; ++l) {
      for (int k = 0; k < 3; ++k) rows[k][l] = in.o[k][begin + l], rows[3 + k][l] = in.d[k][begin + l];
      rows[6][l] = in.t_max[begin + l];
    }
  }
  SetupLanes s;
  setup4(rows, 0, s);
  setup4(rows, 4, s);
  for (std::size_t l = 0; l < n; ++l) {
    status[l] = s.supported[l] ? kWideRaySupported : s.valid[l] ? kWideRayBinary : kWideRayInvalid;
    WideRay& r = out[l];
    for (int k = 0; k < 3; ++k) {
      r.inv[k] = s.inv[k][l], r.o_near[k] = s.near[k][l], r.o_far[k] = s.far[k][l];
      r.near_offset[k] = s.near_off[k][l], r.far_offset[k] = s.far_off[k][l];
      r.ball_o[k] = s.ball_o[k][l], r.ball_d[k] = s.ball_d[k][l];
    }
    r.ball_margin = s.margin[l];
    r.balls = nullptr;
    r.prefetch = false;
  }
}
