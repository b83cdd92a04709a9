// The lane kernels (ray_lanes.inl) compiled for AVX-512 (8 lanes of double; float lanes are the same 8 rays in half
// a register, converted from the batch's double arrays), AVX2 (4 lanes) and scalar (1 lane).
#include "kernels/rays/ray_lanes.hpp"
#include "kernels/rays/ray_quadrics.hpp"

#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>

// The vector types cross no call boundary between instruction sets (each set's functions call only their own).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::kernels::rays {
namespace {

// One hull lane in its local frame, as ray_local() does it for an uninflated hull (polar walk, all-plane clipping
// when the walk gives up), after the caller's lane-wise bounding-ball test: `ball_enter` is where the ray enters the
// ball. Compiled once, outside the instruction-set regions, and called by every build: the same bits on every set
// (and the same as ray_local's: the walk's answer does not depend on where it starts). `isa`: the calling build's
// own set (kLaneIsa), which caps the clipping loop's as it caps the lanes' (the scalar build, which also takes a
// batch's last rays under every cap, runs the baseline loop: the same bits).
template <class T>
__attribute__((noinline)) void hull_lane(const HullPlanes<T>& planes, double bound, const T o[3], const T d[3], T t_max,
                                         T ball_enter, T& enter, T nl[3], int isa) {
  const Vec3<T> vo(o[0], o[1], o[2]), vd(d[0], d[1], d[2]);
  enter = infinity<T>();
  LocalHit<T> h;
  bool ok = false;
  if (planes.walk.planes() > 0)
    h = ray_hull_walk(planes.walk, vo, vd, t_max, ok, hull_walk_start(ball_enter, vo, vd, T(bound)));
  if (!ok) h = finish(ray_convex(vo, vd, planes, isa), vd, t_max);
  if (!h.hit) return;
  enter = h.t;
  nl[0] = h.normal.x(), nl[1] = h.normal.y(), nl[2] = h.normal.z();
}

}  // namespace

// Helpers shared by the vector builds (templates: instantiated inside each target region, for its own set).
#define BATCHCOL_LANE_VECTOR_HELPERS                                                                  \
  inline VD loadd(const double* p) {                                                                  \
    VD v;                                                                                             \
    __builtin_memcpy(&v, p, sizeof v);                                                                \
    return v;                                                                                         \
  }                                                                                                   \
  inline void stored(double* p, VD v) { __builtin_memcpy(p, &v, sizeof v); }                          \
  inline VF to_float(VD x) { return __builtin_convertvector(x, VF); }                                 \
  inline VD to_double(VF x) { return __builtin_convertvector(x, VD); }                                \
  inline void lane_set(VD& v, int l, double x) { v[l] = x; }                                          \
  inline void lane_set(VF& v, int l, float x) { v[l] = x; }                                           \
  inline double lane_get(VD v, int l) { return v[l]; }                                                \
  inline float lane_get(VF v, int l) { return v[l]; }                                                 \
  inline VF float_up(VD t) {                                                                          \
    VF f = to_float(t);                                                                               \
    for (int l = 0; l < W; ++l) {                                                                     \
      if (double(f[l]) < t[l]) {                                                                      \
        float x = f[l];                                                                               \
        std::uint32_t u;                                                                              \
        __builtin_memcpy(&u, &x, sizeof u);                                                           \
        u = x == 0.0f ? 1u : u + 1; /* t >= 0: the next float up */                                   \
        __builtin_memcpy(&x, &u, sizeof u);                                                           \
        f[l] = x;                                                                                     \
      }                                                                                               \
    }                                                                                                 \
    return f;                                                                                         \
  }                                                                                                   \
  template <class Mk> inline Mk mnot(Mk m) { return ~m; }                                             \
  template <class Mk> inline Mk mand(Mk a, Mk b) { return a & b; }                                    \
  template <class Mk> inline Mk mor(Mk a, Mk b) { return a | b; }                                     \
  template <class Mk> inline bool all_true(Mk m) {                                                    \
    for (int l = 0; l < W; ++l)                                                                       \
      if (m[l] == 0) return false;                                                                    \
    return true;                                                                                      \
  }                                                                                                   \
  template <class Mk> inline void store_hits(std::uint8_t* hit, std::uint8_t* status, Mk m) {         \
    for (int l = 0; l < W; ++l) hit[l] = m[l] != 0 ? 1 : 0, status[l] = 0;                            \
  }

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw")
namespace lanes_avx512 {
constexpr int W = 8, kLaneIsa = 2;
typedef double VD __attribute__((vector_size(64)));
typedef float VF __attribute__((vector_size(32)));
inline VD lsqrt(VD a) { return _mm512_sqrt_pd(a); }
inline VF lsqrt(VF a) { return _mm256_sqrt_ps(a); }
BATCHCOL_LANE_VECTOR_HELPERS
#include "kernels/rays/ray_lanes.inl"
}  // namespace lanes_avx512
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx2")
namespace lanes_avx2 {
constexpr int W = 4, kLaneIsa = 1;
typedef double VD __attribute__((vector_size(32)));
typedef float VF __attribute__((vector_size(16)));
inline VD lsqrt(VD a) { return _mm256_sqrt_pd(a); }
inline VF lsqrt(VF a) { return _mm_sqrt_ps(a); }
BATCHCOL_LANE_VECTOR_HELPERS
#include "kernels/rays/ray_lanes.inl"
}  // namespace lanes_avx2
#pragma GCC pop_options

#undef BATCHCOL_LANE_VECTOR_HELPERS

namespace lanes_scalar {
constexpr int W = 1, kLaneIsa = 0;
using VD = double;
using VF = float;
inline double loadd(const double* p) { return *p; }
inline void stored(double* p, double v) { *p = v; }
inline float to_float(double x) { return static_cast<float>(x); }
inline double to_double(float x) { return x; }
inline void lane_set(double& v, int, double x) { v = x; }
inline void lane_set(float& v, int, float x) { v = x; }
inline double lane_get(double v, int) { return v; }
inline float lane_get(float v, int) { return v; }
inline double lsqrt(double a) { return std::sqrt(a); }
inline float lsqrt(float a) { return std::sqrt(a); }
inline float float_up(double t) {
  float f = static_cast<float>(t);
  if (double(f) < t) {
    std::uint32_t u;
    __builtin_memcpy(&u, &f, sizeof u);
    u = f == 0.0f ? 1u : u + 1;
    __builtin_memcpy(&f, &u, sizeof u);
  }
  return f;
}
inline bool mnot(bool m) { return !m; }
inline bool mand(bool a, bool b) { return a && b; }
inline bool mor(bool a, bool b) { return a || b; }
inline bool all_true(bool m) { return m; }
inline void store_hits(std::uint8_t* hit, std::uint8_t* status, bool m) { *hit = m ? 1 : 0, *status = 0; }
#include "kernels/rays/ray_lanes.inl"
}  // namespace lanes_scalar

LaneCasts lane_casts_for(int isa) {
  switch (isa) {
    case 0: return {&lanes_scalar::cast_double, &lanes_scalar::cast_float, 1};
    case 1:
      if (__builtin_cpu_supports("avx2")) return {&lanes_avx2::cast_double, &lanes_avx2::cast_float, 4};
      break;
    case 2:
      if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
          __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw"))
        return {&lanes_avx512::cast_double, &lanes_avx512::cast_float, 8};
      break;
    default: break;
  }
  return {nullptr, nullptr, 0};
}

LaneCasts select_lane_casts() {
  for (int isa = 2; isa > 0; --isa) {
    const LaneCasts c = lane_casts_for(isa);
    if (c.width > 0) return c;
  }
  return lane_casts_for(0);
}

}  // namespace batchcol::kernels::rays
