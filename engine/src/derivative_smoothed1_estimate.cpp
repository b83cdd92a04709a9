// smoothed1's support-Jacobian estimate (smoothed_support_estimate(), derivative_smoothed1.hpp): the supports of the
// perturbed directions and their sums. Moved here from derivative_support.cpp so that the smoothed1 path has its own
// file; since then AVX2 forms (the same bits) of the small-hull scan, the ellipsoid and hull sample differences and
// the sample sums, and the directions two draws per SSE2 register.
#include "derivative_smoothed1.hpp"

#include "derivative_support.hpp"
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

#pragma GCC push_options
#pragma GCC target("avx2")
// scan_hull_sse2() with four directions in one AVX2 register: the same products, sums, comparisons (_CMP_GT_OQ is
// _mm_cmpgt_pd's ordered '>'), maxima (vmaxpd returns its second operand on NaN, as maxpd) and indices (vertex
// numbers counted up in the register, exact), so the same indices.
__attribute__((noinline)) void scan_hull_avx2(const double* v, std::uint32_t count, const double* const* d,
                                              std::size_t n4, double* index) {
  for (std::size_t j0 = 0; j0 < n4; j0 += 4) {
    const __m256d x = _mm256_loadu_pd(d[0] + j0), y = _mm256_loadu_pd(d[1] + j0), w = _mm256_loadu_pd(d[2] + j0);
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
    _mm256_storeu_pd(index + j0, found);
  }
}

// q_j = v_index[j] - s0 for the n samples of a hull without inflation, a masked load, subtraction and store of three
// coordinates each (the scalar copy was ~19 instructions a sample with its index conversions and bound tests).
__attribute__((noinline)) void hull_differences_avx2(const double* v, const double* index, std::size_t n,
                                                     const double* s0, double* q) {
  const __m256i three = _mm256_setr_epi64x(-1, -1, -1, 0);
  const __m256d base = _mm256_maskload_pd(s0, three);
  for (std::size_t j = 0; j < n; ++j) {
    const double* p = v + 3 * static_cast<std::size_t>(index[j]);
    _mm256_maskstore_pd(q + 3 * j, three, _mm256_sub_pd(_mm256_maskload_pd(p, three), base));
  }
}
// The ellipsoid branch of smoothed_support_estimate() (kernels::support()'s formula in its order, zero where
// |r .* d| = 0) four directions per AVX2 register, and q_j = S(d_j) - s0 transposed to three coordinates a sample by
// register shuffles and masked stores: the same bits, half the SSE2 form's instructions per sample.
__attribute__((noinline)) void ellipsoid_differences_avx2(const double* radii, const double* const* d, std::size_t n,
                                                          const double* s0, double* q) {
  const __m256d rx = _mm256_set1_pd(radii[0]), ry = _mm256_set1_pd(radii[1]), rz = _mm256_set1_pd(radii[2]);
  const __m256d bx = _mm256_set1_pd(s0[0]), by = _mm256_set1_pd(s0[1]), bz = _mm256_set1_pd(s0[2]);
  const __m256d zero = _mm256_setzero_pd();
  const __m256i three = _mm256_setr_epi64x(-1, -1, -1, 0);
  for (std::size_t j = 0; j < n; j += 4) {  // the directions are padded with zeros to a multiple of 4
    const __m256d ax = _mm256_mul_pd(rx, _mm256_loadu_pd(d[0] + j));
    const __m256d ay = _mm256_mul_pd(ry, _mm256_loadu_pd(d[1] + j));
    const __m256d az = _mm256_mul_pd(rz, _mm256_loadu_pd(d[2] + j));
    const __m256d m = _mm256_sqrt_pd(
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, ax), _mm256_mul_pd(ay, ay)), _mm256_mul_pd(az, az)));
    const __m256d at_zero = _mm256_cmp_pd(m, zero, _CMP_EQ_OQ);
    const auto point = [&](__m256d r, __m256d a, __m256d base) {
      return _mm256_sub_pd(_mm256_blendv_pd(_mm256_div_pd(_mm256_mul_pd(r, a), m), zero, at_zero), base);
    };
    const __m256d X = point(rx, ax, bx), Y = point(ry, ay, by), Z = point(rz, az, bz);
    const __m256d t0 = _mm256_unpacklo_pd(X, Y), t1 = _mm256_unpackhi_pd(X, Y);  // x0 y0 x2 y2, x1 y1 x3 y3
    const __m256d t2 = _mm256_unpacklo_pd(Z, zero), t3 = _mm256_unpackhi_pd(Z, zero);
    const __m256d rows[4] = {_mm256_permute2f128_pd(t0, t2, 0x20), _mm256_permute2f128_pd(t1, t3, 0x20),
                             _mm256_permute2f128_pd(t0, t2, 0x31), _mm256_permute2f128_pd(t1, t3, 0x31)};
    for (std::size_t l = 0; l < 4 && j + l < n; ++l) _mm256_maskstore_pd(q + 3 * (j + l), three, rows[l]);
  }
}

// The sample sums of smoothed_support_estimate() with row r of s_rc = sum_j +-(S_r - s0_r) z_c in one AVX2 register
// (lane 3 unused): the same products and the same order of additions per entry as its SSE2 form, half the
// instructions (one broadcast, product and sum per row and sample instead of a pair, a scalar and their moves).
// Then, as the SSE2 path's tail, H = sum / scale and S = 0.5 (H + H^T) (written to S: symmetric, so either order), the
// rows divided in registers and H^T by a register transpose instead of nine scalar divisions and Eigen's expression.
__attribute__((noinline)) void sample_sums_avx2(const double* q, const double* const* z, std::size_t draws,
                                                std::size_t n, double scale, double* S) {
  __m256d s[3] = {_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
  for (std::size_t k = 0; k < draws; ++k) {
    const __m256d zk = _mm256_setr_pd(z[0][k], z[1][k], z[2][k], 0.0);
    const double* qj = q + 6 * k;
    for (int r = 0; r < 3; ++r) s[r] = _mm256_add_pd(s[r], _mm256_mul_pd(_mm256_broadcast_sd(qj + r), zk));
    if (2 * k + 1 < n)
      for (int r = 0; r < 3; ++r) s[r] = _mm256_sub_pd(s[r], _mm256_mul_pd(_mm256_broadcast_sd(qj + 3 + r), zk));
  }
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
#pragma GCC pop_options

}  // namespace

Eigen::Matrix3d smoothed_support_estimate(const ShapeView& view, const Eigen::Vector3d& u, double e, int samples,
                                          const double* const* z, InstructionSet isa) {
  const auto core = kernels::make_core<double>(view);
  kernels::SupportHint hint;
  const auto support = [&](const Eigen::Vector3d& d) {
    Eigen::Vector3d p = kernels::support(core, d, hint);
    add_swept_radius(p, core.radius, d);
    return p;
  };
  const Eigen::Vector3d s0 = support(u);
  const bool wide = isa == InstructionSet::avx2 || isa == InstructionSet::avx512;  // the AVX2 forms (the same bits)
  // The noise z comes drawn (the caller draws both sides' at once). All the directions, then the support points,
  // then their sums, each in its own loop: the support call clobbers every vector register, so whatever a loop
  // around it kept (the noise, u, e, the sums) lived on the stack.
  const std::size_t draws = static_cast<std::size_t>(samples + 1) / 2;
  const std::size_t n = static_cast<std::size_t>(samples), n4 = (n + 3) & ~std::size_t(3);
  thread_local std::vector<double> buffer;
  if (buffer.size() < 4 * n4 + 3 * n) buffer.resize(4 * n4 + 3 * n);
  double* const d[3] = {buffer.data(), buffer.data() + n4,
                        buffer.data() + 2 * n4};  // u + e z_j by coordinate, padded with zeros to 4
  double* const q = buffer.data() + 3 * n4;       // S(u + e z_j) - s0, 3 per sample, then a scan's n4 indices
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
  if (view.type == ShapeType::convex && view.hull && !kernels::hull_climbs(*view.hull) &&
      view.hull->vertex_count > 0) {
    // A scanned hull (kernels::hull_support's small-hull path): every direction's first maximum (scan_hull_*()),
    // then the sample points.
    const double* v = view.hull->vertices;
    double* const index_of = q + 3 * n;  // the first maximum's vertex of each direction (n4 of them)
    std::size_t j_done = 0;  // directions whose sample differences are written
    if (wide) scan_hull_avx2(v, view.hull->vertex_count, d, n4, index_of);
    else scan_hull_sse2(v, view.hull->vertex_count, d, n4, index_of);
    if (wide && core.radius == 0.0) {
      hull_differences_avx2(v, index_of, n, s0.data(), q);
      j_done = n4;
    }
    for (std::size_t j0 = j_done; j0 < n4; j0 += 4) {
      const double* const index = index_of + j0;
      const std::size_t lanes = std::min<std::size_t>(4, n - j0);
      if (core.radius == 0.0) {
        for (std::size_t l = 0; l < lanes; ++l) {
          const double* p = v + 3 * static_cast<std::size_t>(index[l]);
          double* qj = q + 3 * (j0 + l);
          qj[0] = p[0] - s0[0], qj[1] = p[1] - s0[1], qj[2] = p[2] - s0[2];
        }
        continue;
      }
      for (std::size_t l = 0; l < lanes; ++l) {
        const std::size_t j = j0 + l;
        const double* p = v + 3 * static_cast<std::size_t>(index[l]);
        Eigen::Vector3d point(p[0], p[1], p[2]);
        add_swept_radius(point, core.radius, Eigen::Vector3d(d[0][j], d[1][j], d[2][j]));  // as support()
        for (int r = 0; r < 3; ++r) q[3 * j + r] = point[r] - s0[r];
      }
    }
  } else if (view.type == ShapeType::ellipsoid && core.radius == 0.0) {
    // kernels::support()'s ellipsoid, two directions per SSE2 register with its operations in its order (rd = r .* d,
    // m = sqrt((rd_x^2 + rd_y^2) + rd_z^2), (r .* rd) / m, zero where m == 0): the same bits without a call per
    // sample (~47 instructions each, callgrind). The directions are padded with zeros to n4.
    if (wide) {
      ellipsoid_differences_avx2(core.size.data(), d, n, s0.data(), q);
    } else {
      const V2 rx = V2{} + core.size.x(), ry = V2{} + core.size.y(), rz = V2{} + core.size.z();
      for (std::size_t j = 0; j < n; j += 2) {
        V2 dx, dy, dz;
        std::memcpy(&dx, d[0] + j, sizeof dx), std::memcpy(&dy, d[1] + j, sizeof dy);
        std::memcpy(&dz, d[2] + j, sizeof dz);
        const V2 ax = rx * dx, ay = ry * dy, az = rz * dz;
        const V2 m = _mm_sqrt_pd((ax * ax + ay * ay) + az * az);
        const M2 zero = m == 0.0;
        const V2 p[3] = {zero ? V2{} : (rx * ax) / m, zero ? V2{} : (ry * ay) / m, zero ? V2{} : (rz * az) / m};
        for (std::size_t l = 0; l < 2 && j + l < n; ++l)
          for (int r = 0; r < 3; ++r) q[3 * (j + l) + r] = p[r][l] - s0[r];
      }
    }
  } else {
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d p = support(Eigen::Vector3d(d[0][j], d[1][j], d[2][j]));
      for (int r = 0; r < 3; ++r) q[3 * j + r] = p[r] - s0[r];
    }
  }
  // Each entry s_rc still adds (S_r - s0_r) z_c sample after sample (q (-z) added is q z subtracted, exactly).
  double sum[3][4];
  if (wide) {
    Eigen::Matrix3d S;
    sample_sums_avx2(q, z, draws, n, static_cast<double>(samples) * e, S.data());
    return S;
  } else {
    // Row r's three entries in one SSE2 pair and a scalar.
    V2 s01[3] = {}, s2v = {};
    double s22 = 0.0;
    const auto add = [&](const double* qj, const V2 z01, double z2v, bool minus) {
      for (int r = 0; r < 3; ++r) {
        const V2 t = qj[r] * z01;
        s01[r] = minus ? s01[r] - t : s01[r] + t;
      }
      const V2 q01 = {qj[0], qj[1]}, t2 = q01 * z2v;
      const double t22 = qj[2] * z2v;
      s2v = minus ? s2v - t2 : s2v + t2;
      s22 = minus ? s22 - t22 : s22 + t22;
    };
    for (std::size_t k = 0; k < draws; ++k) {
      const V2 z01 = {z[0][k], z[1][k]};
      add(q + 6 * k, z01, z[2][k], false);
      if (2 * k + 1 < n) add(q + 6 * k + 3, z01, z[2][k], true);
    }
    for (int r = 0; r < 3; ++r) sum[r][0] = s01[r][0], sum[r][1] = s01[r][1];
    sum[0][2] = s2v[0], sum[1][2] = s2v[1], sum[2][2] = s22;
  }
  Eigen::Matrix3d H;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) H(r, c) = sum[r][c] / (static_cast<double>(samples) * e);
  return (0.5 * (H + H.transpose())).eval();
}

}  // namespace batchcol::detail
