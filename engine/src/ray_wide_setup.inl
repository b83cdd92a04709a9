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

// The first 16 four-byte fields of a WideRay (o_near, o_far, inv, ball_o, ball_d, ball_margin), in their order, as
// vectors of 4 lanes (rays).
constexpr int kRayFields = 16;
static_assert(offsetof(WideRay, o_near) == 0 && offsetof(WideRay, o_far) == 12 && offsetof(WideRay, inv) == 24 &&
                  offsetof(WideRay, ball_o) == 36 && offsetof(WideRay, ball_d) == 48 &&
                  offsetof(WideRay, ball_margin) == 4 * (kRayFields - 1) && offsetof(WideRay, octant) == 4 * kRayFields,
              "store_rays4() writes the fields before `octant` as 4 blocks of 4");

// Writes rays [0, 4) of `f` into out[0..3]: each block of 4 fields is a 4 x 4 transposition (8 shuffles) and one
// 16-byte store per ray, where copying lane by lane cost ~50 instructions a ray (callgrind, AVX2). Only bits move:
// the fields are those the lanes computed, on every instruction set.
inline void store_rays4(const U4 (&f)[kRayFields], WideRay* out) {
  const U4 lo = {0, 4, 1, 5}, hi = {2, 6, 3, 7}, first = {0, 1, 4, 5}, second = {2, 3, 6, 7};
  for (int j = 0; j < kRayFields / 4; ++j) {
    const U4 t0 = __builtin_shuffle(f[4 * j], f[4 * j + 1], lo), t1 = __builtin_shuffle(f[4 * j + 2], f[4 * j + 3], lo);
    const U4 t2 = __builtin_shuffle(f[4 * j], f[4 * j + 1], hi), t3 = __builtin_shuffle(f[4 * j + 2], f[4 * j + 3], hi);
    const U4 ray[4] = {__builtin_shuffle(t0, t1, first), __builtin_shuffle(t0, t1, second),
                       __builtin_shuffle(t2, t3, first), __builtin_shuffle(t2, t3, second)};
    for (int l = 0; l < 4; ++l) __builtin_memcpy(reinterpret_cast<char*>(out + l) + 16 * j, &ray[l], sizeof ray[l]);
  }
}

// Four vectors (one per ray) of four fields each, transposed to four vectors (one per field) of four rays.
inline void transpose4(const D (&v)[4], D (&out)[4]) {
  const L even = {0, 4, 2, 6}, odd = {1, 5, 3, 7}, low = {0, 1, 4, 5}, high = {2, 3, 6, 7};
  const D t0 = __builtin_shuffle(v[0], v[1], even), t1 = __builtin_shuffle(v[0], v[1], odd);
  const D t2 = __builtin_shuffle(v[2], v[3], even), t3 = __builtin_shuffle(v[2], v[3], odd);
  out[0] = __builtin_shuffle(t0, t2, low), out[1] = __builtin_shuffle(t1, t3, low);
  out[2] = __builtin_shuffle(t0, t2, high), out[3] = __builtin_shuffle(t1, t3, high);
}

// Rays [b, b + 4) of the group into out[0..3] (the fields before `octant`), their octants, validity and float-range
// masks.
void setup4(const double (&in)[7][8], int b, WideRay* out, std::uint32_t (&octant_out)[8],
            std::int64_t (&supported_out)[8], std::int64_t (&valid_out)[8]) {
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
  __builtin_memcpy(&supported_out[b], &supported, sizeof supported);
  __builtin_memcpy(&valid_out[b], &valid, sizeof valid);
  U4 f[kRayFields], octant = {0, 0, 0, 0};
  // make_wide_ray().
  const D len = BATCHCOL_SETUP_SQRT(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  D o_length = splat_d(0.0);
  for (int k = 0; k < 3; ++k) {
    const U4 neg = (U4)__builtin_convertvector((L)d[k] < 0, I4);  // the sign bit, -0 included
    const U4 inv = (U4)__builtin_convertvector(splat_d(1.0) / d[k], F4);
    const U4 up = round_up_bits(o[k]), down = round_up_bits(-o[k]) ^ 0x80000000u;  // round_down(x) = -round_up(-x)
    const U4 o_near = (down & neg) | (up & ~neg), o_far = (up & neg) | (down & ~neg);
    const F4 ball_o = __builtin_convertvector(o[k], F4), ball_d = __builtin_convertvector(d[k] / len, F4);
    f[k] = o_near, f[3 + k] = o_far, f[6 + k] = inv, f[9 + k] = (U4)ball_o, f[12 + k] = (U4)ball_d;
    octant |= neg & (1u << k);
    o_length += abs_d(o[k]);
  }
  f[15] = round_up_bits(splat_d(double(kBallMargin)) * o_length);
  store_rays4(f, out);
  __builtin_memcpy(&octant_out[b], &octant, sizeof octant);
}

// The rays of a group from its 7 rows of 8 lanes (a partial group's padding lanes are computed, not written out).
void setup_rows(const double (&rows)[7][8], std::size_t n, WideRay* out, std::uint8_t* status) {
  // A whole group is written in place; a partial one through a local group, of which the first n rays are copied.
  WideRay local[8];
  WideRay* const dst = n == 8 ? out : local;
  std::uint32_t octant[8];
  std::int64_t supported[8], valid[8];
  setup4(rows, 0, dst, octant, supported, valid);
  setup4(rows, 4, dst + 4, octant, supported, valid);
  for (std::size_t l = 0; l < n; ++l) {
    status[l] = supported[l] ? kWideRaySupported : valid[l] ? kWideRayBinary : kWideRayInvalid;
    WideRay& r = dst[l];
    r.octant = octant[l];
    r.balls = nullptr;
    r.ball_stride = 4;
    r.prefetch = false;
    if (dst != out) out[l] = r;
  }
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
  setup_rows(rows, n, out, status);
}

void setup_records(const WideRayRecord* const* records, std::size_t n, WideRay* out, std::uint8_t* status) {
  // Each record is two vectors of 4 doubles, (o x, o y, o z, d x) and (d y, d z, t_max, pad); four records' first
  // (second) vectors transposed 4 x 4 are rows 0-3 (4-6 and the pads) of 4 lanes: 16 loads, 16 shuffles and 14
  // stores for 8 rays, where gathering them field by field cost ~27 instructions a ray (callgrind, AVX2). A partial
  // group pads with the harmless ray of setup_rays(); only bits move, so the rows are those of setup_rays().
  static const WideRayRecord pad{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 0.0, 0.0};
  const WideRayRecord* r[8];
  for (std::size_t l = 0; l < 8; ++l) r[l] = l < n ? records[l] : &pad;
  const auto load = [](const double* p) {
    D v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
  };
  double rows[7][8];
  for (int b = 0; b < 8; b += 4) {
    const D first[4] = {load(r[b]->o), load(r[b + 1]->o), load(r[b + 2]->o), load(r[b + 3]->o)};
    const D second[4] = {load(&r[b]->d[1]), load(&r[b + 1]->d[1]), load(&r[b + 2]->d[1]), load(&r[b + 3]->d[1])};
    D row[4];
    transpose4(first, row);
    __builtin_memcpy(&rows[0][b], &row[0], sizeof(D));
    __builtin_memcpy(&rows[1][b], &row[1], sizeof(D));
    __builtin_memcpy(&rows[2][b], &row[2], sizeof(D));
    __builtin_memcpy(&rows[3][b], &row[3], sizeof(D));
    transpose4(second, row);
    __builtin_memcpy(&rows[4][b], &row[0], sizeof(D));
    __builtin_memcpy(&rows[5][b], &row[1], sizeof(D));
    __builtin_memcpy(&rows[6][b], &row[2], sizeof(D));  // row[3]: the pads
  }
  setup_rows(rows, n, out, status);
}
