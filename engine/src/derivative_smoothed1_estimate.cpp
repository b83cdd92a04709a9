// smoothed1's support-Jacobian estimate (smoothed_support_estimate(), derivative_smoothed1.hpp): the supports of the
// perturbed directions and their sums. Moved here from derivative_support.cpp so that the smoothed1 path has its own
// file; since then AVX2 forms (the same bits) of the small-hull scan, the ellipsoid and hull sample differences and
// the sample sums, and the directions two draws per SSE2 register.
#include "derivative_smoothed1.hpp"

#include "derivative_support.hpp"
#include "shape_table_access.hpp"
#include "kernels/shape_core.hpp"
#include "kernels/support.hpp"

#include <immintrin.h>  // SSE2: the x86-64 baseline this file is compiled for; AVX2 under its target pragma

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

// 32-byte vectors in the AVX2 scan: internal, no ABI crossing.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::detail {
namespace {

using V2 = double __attribute__((vector_size(16)));
using M2 = long long __attribute__((vector_size(16)));  // a V2 compare's lanes: all ones or zero

// The first maximum over a scanned hull's `count` vertices (x y z each) of the dot products (hull_dot's expression in
// double: (x dx + y dy) + z dz) with each of the n4 directions d[c][j] (n4 a multiple of 4), as a double (exact) in
// index[j]: kernels::hull_support's small-hull path, several directions a register instead of a call and a scalar
// scan per direction. max(di, best) is di > best ? di : best (best when either is NaN, as the scalar '>').
// Intrinsics: GCC scalarised the vector-extension selects of this loop through the stack.
// Four directions in two SSE2 registers (~43 instructions a vertex, callgrind).
void scan_hull_sse2(const double* v, std::uint32_t count, const double* const* d, std::size_t n4, double* index) {
  // Each vertex's coordinates and index broadcast once per call (scanned hulls have < kHillClimbMinVertices = 32
  // vertices when built by Shape::convex; a larger hull without blocks broadcasts in the loop).
  constexpr std::uint32_t kKept = 32;
  __m128d kept[4 * kKept];
  const bool keep = count <= kKept && n4 > 4;  // one group of four directions (M <= 4) reads them once
  if (keep) {
    for (std::uint32_t i = 0; i < count; ++i) {
      for (int c = 0; c < 3; ++c) kept[4 * i + c] = _mm_set1_pd(v[3 * std::size_t(i) + c]);
      kept[4 * i + 3] = _mm_set1_pd(double(i));
    }
  }
  for (std::size_t j0 = 0; j0 < n4; j0 += 4) {
    const __m128d x0 = _mm_loadu_pd(d[0] + j0), x1 = _mm_loadu_pd(d[0] + j0 + 2);
    const __m128d y0 = _mm_loadu_pd(d[1] + j0), y1 = _mm_loadu_pd(d[1] + j0 + 2);
    const __m128d w0 = _mm_loadu_pd(d[2] + j0), w1 = _mm_loadu_pd(d[2] + j0 + 2);
    const auto dot = [&](const __m128d& px, const __m128d& py, const __m128d& pz, __m128d& a, __m128d& b) {
      a = _mm_add_pd(_mm_add_pd(_mm_mul_pd(px, x0), _mm_mul_pd(py, y0)), _mm_mul_pd(pz, w0));
      b = _mm_add_pd(_mm_add_pd(_mm_mul_pd(px, x1), _mm_mul_pd(py, y1)), _mm_mul_pd(pz, w1));
    };
    __m128d best0, best1, index0 = _mm_setzero_pd(), index1 = _mm_setzero_pd();
    dot(_mm_set1_pd(v[0]), _mm_set1_pd(v[1]), _mm_set1_pd(v[2]), best0, best1);
    for (std::uint32_t i = 1; i < count; ++i) {
      __m128d d0, d1, at;
      if (keep) {
        dot(kept[4 * i], kept[4 * i + 1], kept[4 * i + 2], d0, d1);
        at = kept[4 * i + 3];
      } else {
        const double* p = v + 3 * std::size_t(i);
        dot(_mm_set1_pd(p[0]), _mm_set1_pd(p[1]), _mm_set1_pd(p[2]), d0, d1);
        at = _mm_set1_pd(double(i));
      }
      const __m128d above0 = _mm_cmpgt_pd(d0, best0), above1 = _mm_cmpgt_pd(d1, best1);
      best0 = _mm_max_pd(d0, best0);
      best1 = _mm_max_pd(d1, best1);
      // index = above ? at : index, as index ^ (above & (index ^ at))
      index0 = _mm_xor_pd(index0, _mm_and_pd(above0, _mm_xor_pd(index0, at)));
      index1 = _mm_xor_pd(index1, _mm_and_pd(above1, _mm_xor_pd(index1, at)));
    }
    _mm_storeu_pd(index + j0, index0);
    _mm_storeu_pd(index + j0 + 2, index1);
  }
}

bool scanned_hull(const HullView& hull) { return !kernels::hull_climbs(hull) && hull.vertex_count > 0; }
bool scanned_hull(const ShapeView& view) {
  return view.type == ShapeType::convex && view.hull && scanned_hull(*view.hull);
}
// estimate4_avx2()'s shapes: no inflation, an ellipsoid or a scanned hull.
inline bool estimate4_case(ShapeType type, double inflation, const HullView& hull) {
  return inflation == 0.0 && (type == ShapeType::ellipsoid || (type == ShapeType::convex && scanned_hull(hull)));
}
// Every other shape's estimate (general_estimate() on the table's ShapeView) into S, defined below.
void general_estimate_of(const ShapeTable& shapes, std::uint32_t shape, const Eigen::Vector3d& u, double e,
                         int samples, const double* const* z, bool wide, double* S);

#pragma GCC push_options
#pragma GCC target("avx2")
// scan_hull_sse2() with four directions in one AVX2 register: the same products, sums, comparisons (_CMP_GT_OQ is
// _mm_cmpgt_pd's ordered '>'), maxima (vmaxpd returns its second operand on NaN, as maxpd) and indices (vertex
// numbers counted up in the register, exact), so the same indices.
// The first maximum's vertex (as a double) of each of the four directions (x, y, w: one coordinate each).
inline __attribute__((always_inline)) __m256d scan4_avx2(const double* v, std::uint32_t count, __m256d x, __m256d y,
                                                        __m256d w) {
  const auto dot = [&](const double* p) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_broadcast_sd(p), x),
                                       _mm256_mul_pd(_mm256_broadcast_sd(p + 1), y)),
                         _mm256_mul_pd(_mm256_broadcast_sd(p + 2), w));
  };
  __m256d best = dot(v), at = _mm256_setzero_pd(), found = at;
  const __m256d one = _mm256_set1_pd(1.0);
  for (std::uint32_t i = 1; i < count; ++i) {
    const __m256d di = dot(v + 3 * std::size_t(i));
    at = _mm256_add_pd(at, one);
    const __m256d above = _mm256_cmp_pd(di, best, _CMP_GT_OQ);
    best = _mm256_max_pd(di, best);
    found = _mm256_blendv_pd(found, at, above);
  }
  return found;
}
__attribute__((noinline)) void scan_hull_avx2(const double* v, std::uint32_t count, const double* const* d,
                                              std::size_t n4, double* index) {
  for (std::size_t j0 = 0; j0 < n4; j0 += 4)
    _mm256_storeu_pd(index + j0, scan4_avx2(v, count, _mm256_loadu_pd(d[0] + j0), _mm256_loadu_pd(d[1] + j0),
                                            _mm256_loadu_pd(d[2] + j0)));
}

// q_k = v_index[2k] - v_index[2k+1] for the `pairs` antithetic pairs of a hull without inflation, two masked loads,
// a subtraction and a store of three coordinates each (the scalar copy was ~19 instructions a sample with its index
// conversions and bound tests).
__attribute__((noinline)) void hull_differences_avx2(const double* v, const double* index, std::size_t pairs,
                                                     double* q) {
  const __m256i three = _mm256_setr_epi64x(-1, -1, -1, 0);
  for (std::size_t k = 0; k < pairs; ++k) {
    const double* plus = v + 3 * static_cast<std::size_t>(index[2 * k]);
    const double* minus = v + 3 * static_cast<std::size_t>(index[2 * k + 1]);
    _mm256_maskstore_pd(q + 3 * k, three,
                        _mm256_sub_pd(_mm256_maskload_pd(plus, three), _mm256_maskload_pd(minus, three)));
  }
}
// The ellipsoid branch of smoothed_support_estimate() (kernels::support()'s formula in its order, zero where
// |r .* d| = 0) four directions (two antithetic pairs) per AVX2 register, and q_k = S(d_2k) - S(d_2k+1) (each lane
// minus its neighbour) transposed to three coordinates a pair by register shuffles and masked stores: the same bits
// as the SSE2 form, half its instructions per sample.
// kernels::support()'s ellipsoid formula (r .* r .* d / |r .* d|, zero where |r .* d| = 0) for four directions
// (two antithetic pairs) in one register, then each lane minus its neighbour: lanes 0 and 2 of q[c] hold coordinate
// c of S(d_2k) - S(d_2k+1). One operation order for both callers, so both give the SSE2 form's bits.
inline __attribute__((always_inline)) void ellipsoid_differences4(const __m256d r[3], const __m256d d[3],
                                                                  __m256d q[3]) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d a[3] = {_mm256_mul_pd(r[0], d[0]), _mm256_mul_pd(r[1], d[1]), _mm256_mul_pd(r[2], d[2])};
  const __m256d m = _mm256_sqrt_pd(
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a[0], a[0]), _mm256_mul_pd(a[1], a[1])), _mm256_mul_pd(a[2], a[2])));
  const __m256d at_zero = _mm256_cmp_pd(m, zero, _CMP_EQ_OQ);
  for (int c = 0; c < 3; ++c) {
    const __m256d p = _mm256_blendv_pd(_mm256_div_pd(_mm256_mul_pd(r[c], a[c]), m), zero, at_zero);
    q[c] = _mm256_sub_pd(p, _mm256_permute_pd(p, 0x5));
  }
}
__attribute__((noinline)) void ellipsoid_differences_avx2(const double* radii, const double* const* d,
                                                          std::size_t pairs, double* q) {
  const __m256d r[3] = {_mm256_set1_pd(radii[0]), _mm256_set1_pd(radii[1]), _mm256_set1_pd(radii[2])};
  const __m256d zero = _mm256_setzero_pd();
  const __m256i three = _mm256_setr_epi64x(-1, -1, -1, 0);
  for (std::size_t j = 0; j < 2 * pairs; j += 4) {  // the directions are padded with zeros to a multiple of 4
    const __m256d dj[3] = {_mm256_loadu_pd(d[0] + j), _mm256_loadu_pd(d[1] + j), _mm256_loadu_pd(d[2] + j)};
    __m256d x[3];
    ellipsoid_differences4(r, dj, x);
    const __m256d t0 = _mm256_unpacklo_pd(x[0], x[1]), t2 = _mm256_unpacklo_pd(x[2], zero);  // x0 y0 x2 y2, z0 0 z2 0
    _mm256_maskstore_pd(q + 3 * (j / 2), three, _mm256_permute2f128_pd(t0, t2, 0x20));
    if (j / 2 + 1 < pairs) _mm256_maskstore_pd(q + 3 * (j / 2 + 1), three, _mm256_permute2f128_pd(t0, t2, 0x31));
  }
}

// H = sum / scale and S = 0.5 (H + H^T) from the sums' rows s[r] (lane 3 unused; written to S: symmetric, so
// either order), the rows divided in registers and H^T by a register transpose instead of nine scalar divisions and
// Eigen's expression: the SSE2 path's operations.
inline __attribute__((always_inline)) void sums_to_estimate_avx2(const __m256d* s, double scale, double* S) {
  const __m256d by = _mm256_set1_pd(scale), half = _mm256_set1_pd(0.5), zero = _mm256_setzero_pd();
  const __m256d h0 = _mm256_div_pd(s[0], by), h1 = _mm256_div_pd(s[1], by), h2 = _mm256_div_pd(s[2], by);
  const __m256d t0 = _mm256_unpacklo_pd(h0, h1), t1 = _mm256_unpackhi_pd(h0, h1);    // h00 h10 h02 h12, h01 h11 ..
  const __m256d t2 = _mm256_unpacklo_pd(h2, zero), t3 = _mm256_unpackhi_pd(h2, zero);  // h20 0 h22 0, h21 0 ..
  const __m256d c0 = _mm256_permute2f128_pd(t0, t2, 0x20), c1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  const __m256d c2 = _mm256_permute2f128_pd(t0, t2, 0x31);  // columns 0, 1, 2 of H (lane 3: 0)
  double rows[3][4];
  _mm256_storeu_pd(rows[0], _mm256_mul_pd(half, _mm256_add_pd(h0, c0)));
  _mm256_storeu_pd(rows[1], _mm256_mul_pd(half, _mm256_add_pd(h1, c1)));
  _mm256_storeu_pd(rows[2], _mm256_mul_pd(half, _mm256_add_pd(h2, c2)));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) S[3 * r + c] = rows[r][c];
}

// The sample sums of smoothed_support_estimate() with row r of s_rc = sum_k q_kr z_ck in one AVX2 register (lane 3
// unused): the same products and the same order of additions per entry as its SSE2 form, half the instructions
// (one broadcast, product and sum per row and draw instead of a pair, a scalar and their moves), then the estimate.
__attribute__((noinline)) void sample_sums_avx2(const double* q, const double* const* z, std::size_t draws,
                                                double scale, double* S) {
  __m256d s[3] = {_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
  for (std::size_t k = 0; k < draws; ++k) {
    const __m256d zk = _mm256_setr_pd(z[0][k], z[1][k], z[2][k], 0.0);
    const double* qk = q + 3 * k;
    for (int r = 0; r < 3; ++r) s[r] = _mm256_add_pd(s[r], _mm256_mul_pd(_mm256_broadcast_sd(qk + r), zk));
  }
  sums_to_estimate_avx2(s, scale, S);
}
// smoothed_support_estimate() at M = 4 (two antithetic pairs) of a scanned hull or an ellipsoid without inflation,
// from the noise to S in registers: the four directions one register per coordinate (lanes u + e z_0, u - e z_0,
// u + e z_1, u - e z_1, as the direction loop), the scan or the ellipsoid formula on them, the pairs' differences,
// the two draws' sums and the estimate, each with the general path's operations in its order (the same bits). The
// general path's buffers, loops and calls were ~580 instructions a side with its scan (callgrind AVX2, convex8).
// The shape by its table index: its type, radii (ellipsoid) and hull (convex) read here from ShapeTableAccess's
// arrays, so that the caller passes six arguments in registers and saves one register (a ShapeView built per side was
// ~45 instructions; the caller's frame and radii copy ~45 a call, callgrind AVX2).
__attribute__((noinline)) void estimate4_avx2(const ShapeTable& shapes, std::uint32_t shape,
                                              const Eigen::Vector3d& u_vector, double e, const double* const* z,
                                              double* S) {
  // The shape test here rather than in smoothed_support_estimate(), whose frame then held the arguments for the
  // general path (~25 instructions a call, callgrind AVX2): other shapes go on from here.
  const ShapeType type = ShapeTableAccess::types(shapes)[shape];
  const HullView& hull = ShapeTableAccess::hulls(shapes)[shape];
  if (!estimate4_case(type, ShapeTableAccess::inflations(shapes)[shape], hull))
    return general_estimate_of(shapes, shape, u_vector, e, 4, z, true, S);
  const double* u = u_vector.data();
  // Coordinate c's two draws (z_c0, z_c1) one 16-byte load, in both halves of a register (M = 4 reads z[c][0 .. 1]
  // only): (z_c0, z_c0, z_c1, z_c1) for the directions and, by unpacks, the draws' rows (z_0k, z_1k, z_2k, 0) with
  // the same values as element loads (~15 instructions a side fewer than the loads and inserts, callgrind AVX2).
  const __m256d zero = _mm256_setzero_pd();
  const __m256d b[3] = {_mm256_broadcast_pd(reinterpret_cast<const __m128d*>(z[0])),
                        _mm256_broadcast_pd(reinterpret_cast<const __m128d*>(z[1])),
                        _mm256_broadcast_pd(reinterpret_cast<const __m128d*>(z[2]))};  // z_c0 z_c1 z_c0 z_c1
  const __m256d ev = _mm256_set1_pd(e);
  __m256d d[3];
  for (int c = 0; c < 3; ++c) {
    const __m256d uv = _mm256_set1_pd(u[c]), ez = _mm256_mul_pd(ev, _mm256_permute_pd(b[c], 0xC));
    d[c] = _mm256_blend_pd(_mm256_add_pd(uv, ez), _mm256_sub_pd(uv, ez), 0xA);
  }
  const __m256d z0 = _mm256_blend_pd(_mm256_unpacklo_pd(b[0], b[1]), _mm256_unpacklo_pd(b[2], zero), 0xC);
  const __m256d z1 = _mm256_blend_pd(_mm256_unpackhi_pd(b[0], b[1]), _mm256_unpackhi_pd(b[2], zero), 0xC);
  // q[c]: lanes 0 and 2 hold coordinate c of S(d_0) - S(d_1) and S(d_2) - S(d_3).
  __m256d q[3];
  if (type == ShapeType::convex) {
    // scan4_avx2()'s first maximum with the vertex's coordinates blended along instead of its number: the same
    // comparisons pick the same vertex, whose coordinates are copied exactly, so the same differences; no index
    // conversions, masked loads or transposes after the scan (~40 instructions a side fewer, callgrind AVX2).
    const double* p = hull.vertices;
    const double* const end = p + 3 * std::size_t(hull.vertex_count);
    const auto dot = [&](__m256d x, __m256d y, __m256d w) {
      return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, d[0]), _mm256_mul_pd(y, d[1])), _mm256_mul_pd(w, d[2]));
    };
    __m256d fx = _mm256_broadcast_sd(p), fy = _mm256_broadcast_sd(p + 1), fz = _mm256_broadcast_sd(p + 2);
    __m256d best = dot(fx, fy, fz);
    for (p += 3; p < end; p += 3) {
      const __m256d x = _mm256_broadcast_sd(p), y = _mm256_broadcast_sd(p + 1), w = _mm256_broadcast_sd(p + 2);
      const __m256d di = dot(x, y, w);
      const __m256d above = _mm256_cmp_pd(di, best, _CMP_GT_OQ);
      best = _mm256_max_pd(di, best);
      fx = _mm256_blendv_pd(fx, x, above), fy = _mm256_blendv_pd(fy, y, above), fz = _mm256_blendv_pd(fz, w, above);
    }
    q[0] = _mm256_sub_pd(fx, _mm256_permute_pd(fx, 0x5));
    q[1] = _mm256_sub_pd(fy, _mm256_permute_pd(fy, 0x5));
    q[2] = _mm256_sub_pd(fz, _mm256_permute_pd(fz, 0x5));
  } else {
    const __m256d r3[3] = {_mm256_set1_pd(ShapeTableAccess::sizes(shapes, 0)[shape]),
                           _mm256_set1_pd(ShapeTableAccess::sizes(shapes, 1)[shape]),
                           _mm256_set1_pd(ShapeTableAccess::sizes(shapes, 2)[shape])};
    ellipsoid_differences4(r3, d, q);
  }
  __m256d s[3];
  for (int r = 0; r < 3; ++r)  // lanes 0 and 2: q_0r, q_1r
    s[r] = _mm256_add_pd(_mm256_add_pd(zero, _mm256_mul_pd(_mm256_permute4x64_pd(q[r], 0x00), z0)),
                         _mm256_mul_pd(_mm256_permute4x64_pd(q[r], 0xAA), z1));
  sums_to_estimate_avx2(s, 4.0 * e, S);
}

#pragma GCC pop_options

// smoothed_support_estimate() on every path but estimate4_avx2()'s, into S (column-major, as Matrix3d::data()).
// Inlined into general_estimate_of(), which is out of line: its frame and register saves cost the M = 4 path ~67
// instructions a side when they were the caller's (callgrind AVX2).
inline __attribute__((always_inline)) void general_estimate(const ShapeView& view, const Eigen::Vector3d& u, double e,
                                                            int samples, const double* const* z, bool wide,
                                                            double* S) {
  const bool scanned = scanned_hull(view);
  const auto core = kernels::make_core<double>(view);
  kernels::SupportHint hint;
  const auto support = [&](const Eigen::Vector3d& d) {
    Eigen::Vector3d p = kernels::support(core, d, hint);
    add_swept_radius(p, core.radius, d);
    return p;
  };
  // The noise z comes drawn (the caller draws both sides' at once). All the directions, then the support points,
  // then their sums, each in its own loop: the support call clobbers every vector register, so whatever a loop
  // around it kept (the noise, u, e, the sums) lived on the stack.
  const std::size_t draws = static_cast<std::size_t>(samples + 1) / 2;
  const std::size_t n = static_cast<std::size_t>(samples), n4 = (n + 3) & ~std::size_t(3);
  const std::size_t pairs = n / 2;  // antithetic pairs; an odd M's last sample has no copy
  thread_local std::vector<double> buffer;
  if (buffer.size() < 4 * n4 + 3 * n) buffer.resize(4 * n4 + 3 * n);
  double* const d[3] = {buffer.data(), buffer.data() + n4,
                        buffer.data() + 2 * n4};  // u + e z_j by coordinate, padded with zeros to 4
  // q_k = S(u + e z_k) - S(u - e z_k) per antithetic pair k (3 each), and an odd M's last q = S(u + e z) - S(u);
  // after them a scan's n4 indices. The pair's two terms (S(u + e z) - S(u)) z and (S(u - e z) - S(u)) (-z) sum to
  // q_k z exactly in real arithmetic: the baseline S(u) cancels, so it is neither computed nor subtracted for
  // even M (one support call per side fewer, one product per pair instead of two; callgrind AVX2 convex8 M = 4:
  // -453 instructions a pair). The rounding differs from the former per-sample form (S(u+ez) - S(u)) - (S(u-ez) -
  // S(u)) (the bits changed; the estimator did not).
  double* const q = buffer.data() + 3 * n4;
  // Sample 2k adds e z_k, its antithetic copy 2k+1 subtracts it: u + e (-z) and u - e z are the same bits.
  // Two draws per SSE2 register (the same products and sums; the scalar loop, ~24 instructions per two draws and
  // coordinate, was ~70 per side at M = 4, callgrind): {u + e z_k, u + e z_k+1} and {u - e z_k, u - e z_k+1}
  // interleaved to the samples' order.
  const V2 ev = V2{} + e;
#pragma GCC unroll 3
  for (int c = 0; c < 3; ++c) {
    const double uc = u[c];
    const V2 uv = V2{} + uc;
    double* dc = d[c];
    std::size_t k = 0;
    for (; k + 2 <= draws; k += 2) {  // an odd M's unused copy lands in the padding (n4 > n)
      V2 zk;
      std::memcpy(&zk, z[c] + k, sizeof zk);
      const V2 ez = ev * zk, plus = uv + ez, minus = uv - ez;
      const V2 first = __builtin_shufflevector(plus, minus, 0, 2), second = __builtin_shufflevector(plus, minus, 1, 3);
      std::memcpy(dc + 2 * k, &first, sizeof first);
      std::memcpy(dc + 2 * k + 2, &second, sizeof second);
    }
    if (k < draws) {
      const double ez = e * z[c][k];
      dc[2 * k] = uc + ez;
      dc[2 * k + 1] = uc - ez;
    }
    if (n4 > n) std::fill(dc + n, dc + n4, 0.0);  // GCC called memset for the empty fill (M = 4: ~120 a pair)
  }
  const auto direction = [&](std::size_t j) { return Eigen::Vector3d(d[0][j], d[1][j], d[2][j]); };
  if (scanned) {
    // A scanned hull (kernels::hull_support's small-hull path): every direction's first maximum (scan_hull_*()),
    // then the pairs' differences.
    const double* v = view.hull->vertices;
    double* const index_of = q + 3 * n;  // the first maximum's vertex of each direction (n4 of them)
    if (wide) scan_hull_avx2(v, view.hull->vertex_count, d, n4, index_of);
    else scan_hull_sse2(v, view.hull->vertex_count, d, n4, index_of);
    if (wide && core.radius == 0.0) {
      hull_differences_avx2(v, index_of, pairs, q);
    } else {
      const auto point = [&](std::size_t j) {  // as support()
        const double* p = v + 3 * static_cast<std::size_t>(index_of[j]);
        Eigen::Vector3d x(p[0], p[1], p[2]);
        if (core.radius != 0.0) add_swept_radius(x, core.radius, direction(j));
        return x;
      };
      for (std::size_t k = 0; k < pairs; ++k) {
        const Eigen::Vector3d plus = point(2 * k), minus = point(2 * k + 1);
        for (int r = 0; r < 3; ++r) q[3 * k + r] = plus[r] - minus[r];
      }
    }
  } else if (view.type == ShapeType::ellipsoid && core.radius == 0.0) {
    // kernels::support()'s ellipsoid, two directions (an antithetic pair) per SSE2 register with its operations in
    // its order (rd = r .* d, m = sqrt((rd_x^2 + rd_y^2) + rd_z^2), (r .* rd) / m, zero where m == 0): the same bits
    // without a call per sample (~47 instructions each, callgrind). The directions are padded with zeros to n4.
    if (wide) {
      ellipsoid_differences_avx2(core.size.data(), d, pairs, q);
    } else {
      const V2 rx = V2{} + core.size.x(), ry = V2{} + core.size.y(), rz = V2{} + core.size.z();
      for (std::size_t k = 0; k < pairs; ++k) {
        V2 dx, dy, dz;
        std::memcpy(&dx, d[0] + 2 * k, sizeof dx), std::memcpy(&dy, d[1] + 2 * k, sizeof dy);
        std::memcpy(&dz, d[2] + 2 * k, sizeof dz);
        const V2 ax = rx * dx, ay = ry * dy, az = rz * dz;
        const V2 m = _mm_sqrt_pd((ax * ax + ay * ay) + az * az);
        const M2 zero = m == 0.0;
        const V2 p[3] = {zero ? V2{} : (rx * ax) / m, zero ? V2{} : (ry * ay) / m, zero ? V2{} : (rz * az) / m};
        for (int r = 0; r < 3; ++r) q[3 * k + r] = p[r][0] - p[r][1];
      }
    }
  } else {
    for (std::size_t k = 0; k < pairs; ++k) {
      const Eigen::Vector3d plus = support(direction(2 * k)), minus = support(direction(2 * k + 1));
      for (int r = 0; r < 3; ++r) q[3 * k + r] = plus[r] - minus[r];
    }
  }
  if (pairs < draws) {  // odd M: the last sample against the baseline (the same point on every path)
    const Eigen::Vector3d s0 = support(u), last = support(direction(n - 1));
    for (int r = 0; r < 3; ++r) q[3 * pairs + r] = last[r] - s0[r];
  }
  // Each entry s_rc adds q_kr z_ck draw after draw.
  double sum[3][4];
  if (wide) {
    sample_sums_avx2(q, z, draws, static_cast<double>(samples) * e, S);
    return;
  } else {
    // Row r's three entries in one SSE2 pair and a scalar.
    V2 s01[3] = {}, s2v = {};
    double s22 = 0.0;
    for (std::size_t k = 0; k < draws; ++k) {
      const V2 z01 = {z[0][k], z[1][k]};
      const double z2v = z[2][k], *qk = q + 3 * k;
      for (int r = 0; r < 3; ++r) s01[r] = s01[r] + qk[r] * z01;
      const V2 q01 = {qk[0], qk[1]};
      s2v = s2v + q01 * z2v;
      s22 = s22 + qk[2] * z2v;
    }
    for (int r = 0; r < 3; ++r) sum[r][0] = s01[r][0], sum[r][1] = s01[r][1];
    sum[0][2] = s2v[0], sum[1][2] = s2v[1], sum[2][2] = s22;
  }
  Eigen::Matrix3d H;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) H(r, c) = sum[r][c] / (static_cast<double>(samples) * e);
  Eigen::Map<Eigen::Matrix3d> out(S);
  out = 0.5 * (H + H.transpose());
}

// Every path but estimate4_avx2()'s, out of line with the ShapeView it builds: its frame (six saved registers, the
// view on the stack) was ~70 instructions a call of smoothed_support_estimate() on the M = 4 path as well. It writes
// S itself: a returned Matrix3d copied to S was ~14 instructions a call (convex8 M = 16, callgrind AVX2).
__attribute__((noinline)) void general_estimate_of(const ShapeTable& shapes, std::uint32_t shape,
                                                   const Eigen::Vector3d& u, double e, int samples,
                                                   const double* const* z, bool wide, double* S) {
  general_estimate(ShapeTableAccess::view(shapes, shape), u, e, samples, z, wide, S);
}

}  // namespace

Eigen::Matrix3d smoothed_support_estimate(const ShapeTable& shapes, std::uint32_t shape, const Eigen::Vector3d& u,
                                          double e, int samples, const double* const* z, InstructionSet isa) {
  const bool wide = isa == InstructionSet::avx2 || isa == InstructionSet::avx512;  // the AVX2 forms (the same bits)
  Eigen::Matrix3d S;
  if (wide && samples == 4) estimate4_avx2(shapes, shape, u, e, z, S.data());  // or its general path
  else general_estimate_of(shapes, shape, u, e, samples, z, wide, S.data());
  return S;
}

}  // namespace batchcol::detail
