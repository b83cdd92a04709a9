#include "derivative_ift.hpp"

#include <Eigen/Eigenvalues>

#include <immintrin.h>  // the lanes' square roots (SSE2 here; AVX2 / AVX-512 under their target pragmas)

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

// 64-byte vectors in the AVX-512 / AVX2 blocks (derivative_lanes.inl): internal, inlined, no ABI crossing.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::detail {
namespace {

PairJacobians constrained_jacobians(const PairGeometry& g);

void set_nan(PairJacobians& J) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Mat36* m : {&J.witness_a_a, &J.witness_a_b, &J.witness_b_a, &J.witness_b_b, &J.normal_a, &J.normal_b})
    m->setConstant(nan);
}

// Writes a pair's 120 entries from the derivatives with respect to the twist of a (wa = dx_a/dxi_a, wb =
// dx_b/dxi_a, dn = dn/dxi_a): the distance gradients by the envelope theorem and the twist of b by the rigid-motion
// identity J_a + J_b = [I, -[x]x] (points), [0, -[n]x] (normal), which the implicit-function formulas satisfy
// exactly when z = sd n (GJK's witness points, to rounding): half the products of solving for b as well.
void write_from_twist_a(const double n[3], const double xa[3], const double xb[3], const double wa[3][6],
                        const double wb[3][6], const double dn[3][6], double* s, std::size_t st) {
  s[0] = -n[0], s[st] = -n[1], s[2 * st] = -n[2];
  s[3 * st] = n[1] * xa[2] - n[2] * xa[1];
  s[4 * st] = n[2] * xa[0] - n[0] * xa[2];
  s[5 * st] = n[0] * xa[1] - n[1] * xa[0];
  s[6 * st] = n[0], s[7 * st] = n[1], s[8 * st] = n[2];
  s[9 * st] = xb[1] * n[2] - xb[2] * n[1];
  s[10 * st] = xb[2] * n[0] - xb[0] * n[2];
  s[11 * st] = xb[0] * n[1] - xb[1] * n[0];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 6; ++j) {
      const std::size_t e = 6 * i + j;
      s[(store_at::witness_a_a + e) * st] = wa[i][j];
      s[(store_at::witness_a_b + e) * st] = -wa[i][j];  // plus x_a's rigid motion below
      s[(store_at::witness_b_a + e) * st] = wb[i][j];
      s[(store_at::witness_b_b + e) * st] = -wb[i][j];  // plus x_b's
      s[(store_at::normal_a + e) * st] = dn[i][j];
      s[(store_at::normal_b + e) * st] = -dn[i][j];  // plus the normal's
    }
  // The rigid motions [I, -[x]x] of x_a (witness_a_b), x_b (witness_b_b) and [0, -[n]x] of the normal (normal_b):
  // -[x]x has x_2 at (0, 1), -x_1 at (0, 2), -x_2 at (1, 0), x_0 at (1, 2), x_1 at (2, 0), -x_0 at (2, 1).
  const auto add_rigid = [&](std::size_t block, const double* x, bool point) {
    if (point)
      for (std::size_t i = 0; i < 3; ++i) s[(block + 7 * i) * st] += 1.0;
    s[(block + 4) * st] += x[2], s[(block + 5) * st] -= x[1], s[(block + 9) * st] -= x[2];
    s[(block + 11) * st] += x[0], s[(block + 15) * st] += x[1], s[(block + 16) * st] -= x[0];
  };
  add_rigid(store_at::witness_a_b, xa, true);
  add_rigid(store_at::witness_b_b, xb, true);
  add_rigid(store_at::normal_b, n, false);
}

// Two lanes per register (the SSE2 width every x86-64 has; this file is compiled for the baseline set), written
// with GCC/Clang vector extensions: elementwise IEEE operations, so every lane rounds as the scalar code would.
using V = double __attribute__((vector_size(16)));

// A whole block (kLanes pairs to columns 0 .. kLanes - 1): the wide sets' one-register path, and run_lanes()'s
// fixed-trip-count case.
// (Early exits: the and-accumulating loop ran all `count` iterations, 7.5 instructions per analytic hull pair,
// callgrind AVX2.)
template <std::size_t kLanes> bool whole_block(std::size_t count, const std::size_t* column) {
  if (count != kLanes) return false;
  for (std::size_t l = 0; l < kLanes; ++l)
    if (column[l] != l) return false;
  return true;
}

// Lanes 0 .. count - 1 go to columns 0 .. count - 1 (1 <= count): a block AVX-512 runs in one register, with a lane
// mask when count < kLanes.
inline bool in_order(std::size_t count, const std::size_t* column) {
  if (count == 0) return false;
  for (std::size_t l = 0; l < count; ++l)
    if (column[l] != l) return false;
  return true;
}

// Runs body(l, both, put) for every register of two lanes l, l + 1 < count (both: the second lane is used), put(e,
// v) writing entry e of the register to out[e][column[lane]]. Compiled twice, so that the common case (a full block
// of whole registers to consecutive columns) has a fixed trip count, whole-vector stores and no per-store test.
template <std::size_t kLanes, class Body>
void run_lanes(std::size_t count, const std::size_t* column, double* const* out, std::size_t at, const Body& body) {
  const bool columns_in_order = whole_block<kLanes>(count, column);
  const auto run = [&](auto in_order_tag) {
    constexpr bool in_order = decltype(in_order_tag)::value;
    const std::size_t lanes = in_order ? kLanes : count;
    for (std::size_t l = 0; l < lanes; l += 2) {
      const bool both = in_order || l + 1 < count;
      // Typed stores (a vector of doubles, 8-byte aligned), not memcpy: a memcpy may alias anything, so the compiler
      // reloaded out and l through the closure before each of the 120 stores (~300 instructions per pair).
      using Unaligned = double __attribute__((vector_size(16), aligned(8)));
      const auto put = [out, at, column, l, both](int e, V v) {
        if (in_order && both) {
          *reinterpret_cast<Unaligned*>(out[e] + at + l) = v;
        } else {
          out[e][at + column[l]] = v[0];
          if (both) out[e][at + column[l + 1]] = v[1];
        }
      };
      body(l, put);
    }
  };
  if (columns_in_order) run(std::true_type{});
  else run(std::false_type{});
}

}  // namespace

// The lanes' bodies (derivative_lanes.inl): two lanes per SSE2 register for any block, and a whole block of eight
// lanes in one AVX-512 register (two AVX2 registers) for the wide sets. PolytopeLanes::solve() in SSE2 was ~500
// instructions per hull pair (callgrind, AVX2 build), a third of the analytic derivative's own cost.
// Each set has its own sqrt_lanes() for the .inl's square roots because GCC emitted one scalar sqrt per lane, with
// the lane moves, for the element-wise form; IEEE square roots are correctly rounded, so every lane still gets
// std::sqrt()'s bits. Likewise select_positive(z, a, b), z > 0 ? a : b lane by lane (ordered: b where z is NaN):
// GCC compiled the vector extension's `?:` on eight lanes as a scalar compare and mask per lane (+~100
// instructions per ellipsoid pair in AVX2 for the curvature's and the rotations' five selects, callgrind). They sit
// in anonymous namespaces: internal linkage, like everything in the .inl.
namespace {
using V8 = double __attribute__((vector_size(64)));
}  // namespace
namespace lanes_base {
namespace {
inline __attribute__((always_inline)) V sqrt_lanes(const V& x) { return (V)_mm_sqrt_pd((__m128d)x); }
inline __attribute__((always_inline)) V select_positive(const V& z, const V& a, const V& b) {
  const __m128d gt = _mm_cmpgt_pd((__m128d)z, _mm_setzero_pd());
  return (V)_mm_or_pd(_mm_and_pd(gt, (__m128d)a), _mm_andnot_pd(gt, (__m128d)b));
}
}  // namespace
#include "derivative_lanes.inl"
}  // namespace lanes_base
#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw")
namespace lanes_avx512 {
namespace {
// The wide blocks' output store, p[at .. at + 8) = v: one register.
inline __attribute__((always_inline)) void store_lanes(double* p, std::size_t at, const V8& v) {
  __builtin_memcpy(p + at, &v, sizeof v);
}
inline __attribute__((always_inline)) V8 sqrt_lanes(const V8& x) {
  // The masked form: _mm512_sqrt_pd()'s undefined source trips GCC 12's -Wuninitialized.
  return (V8)_mm512_mask_sqrt_pd((__m512d)x, 0xFF, (__m512d)x);
}
inline __attribute__((always_inline)) V8 select_positive(const V8& z, const V8& a, const V8& b) {
  const __mmask8 gt = _mm512_cmp_pd_mask((__m512d)z, _mm512_setzero_pd(), _CMP_GT_OQ);
  return (V8)_mm512_mask_blend_pd(gt, (__m512d)b, (__m512d)a);
}
}  // namespace
#include "derivative_lanes.inl"
namespace {
// The permutation of a line that starts `shift` pairs before a block: lane j takes lane j + 8 - shift of the pair
// (carry, block), i.e. the carry's last `shift` entries, then the block's first 8 - shift.
__m512i line_index(std::int64_t shift) {
  return _mm512_add_epi64(_mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0), _mm512_set1_epi64(8 - shift));
}
// A block of `count` pairs to columns 0 .. count - 1 of out[e] + at, one register whatever the count: fewer than
// kLanes pairs (a task range's first and last blocks, StoreBlock's line alignment) with a lane mask, whole blocks
// with plain stores, or in whole lines with non-temporal stores (StreamRows; e is a constant in each store after
// unrolling, so a row's test is one bit test of a register). The lanes' arithmetic does not depend on the store:
// the same bits.
template <class Block> void store_block(std::size_t count, StreamRows* stream, double* const* out, std::size_t at,
                                        const Block& block) {
  if (count < 8) {
    const __mmask8 mask = static_cast<__mmask8>((1u << count) - 1);
    block([out, at, mask](int e, const V8& v) { _mm512_mask_storeu_pd(out[e] + at, mask, (__m512d)v); });
  } else if (stream) {
    const std::uint64_t low = stream->whole[0], high = stream->whole[1];
    const bool carried = stream->carried;
    StreamRows& rows = *stream;
    block([out, at, low, high, carried, &rows](int e, const V8& v) {
      if ((e < 64 ? low >> e : high >> (e - 64)) & 1) return _mm512_stream_pd(out[e] + at, (__m512d)v);
      // Lane j of the line: carry lane j + 8 - shift for j < shift, this block's lane j - shift after.
      const std::int64_t shift = rows.shift[e];
      const __m512i index = line_index(shift);
      // Not carried: the line's first `shift` lanes are masked off below, so the carry (never written yet in a
      // range's first streamed block) is not read at all.
      const __m512d previous = carried ? _mm512_load_pd(rows.carry[e]) : _mm512_setzero_pd();
      const __m512d line = _mm512_permutex2var_pd(previous, index, (__m512d)v);
      // The line's start may lie before the array (at < shift, its lanes masked off): integer arithmetic, since a
      // pointer before its array is undefined even when never dereferenced.
      double* const start = reinterpret_cast<double*>(reinterpret_cast<std::uintptr_t>(out[e] + at) -
                                                      static_cast<std::uintptr_t>(shift) * sizeof(double));
      if (carried) _mm512_stream_pd(start, line);
      else _mm512_mask_storeu_pd(start, static_cast<__mmask8>(0xFFu << shift), line);
      _mm512_store_pd(rows.carry[e], (__m512d)v);
    });
  } else {
    block([out, at](int e, const V8& v) { store_lanes(out[e], at, v); });
  }
}
template <bool kNormalB, bool kCurved, bool kGiven>
void smooth_to(const SmoothLanes& s, std::size_t count, StreamRows* stream, double* const* out,
               std::size_t at) {
  store_block(count, stream, out, at, [&s](const auto& store) {
    smooth_block<V8, kNormalB, kCurved, kGiven>(s, store);
  });
}
void polytope_to(const PolytopeLanes& lanes, std::size_t count, StreamRows* stream, double* const* out,
                 std::size_t at) {
  store_block(count, stream, out, at, [&lanes](const auto& store) { polytope_block<V8>(lanes, store); });
}
}  // namespace
void flush_stream_carry(StreamRows& rows, double* const* out, std::size_t at) {
  for (int e = 0; e < StoreEntries; ++e) {
    const std::int64_t shift = rows.shift[e];
    if (shift == 0) continue;
    // The line after the block's: its first `shift` lanes are the block's last.
    const __m512i index = line_index(shift);
    const __m512d carry = _mm512_load_pd(rows.carry[e]);
    _mm512_mask_storeu_pd(out[e] + at + 8 - shift, static_cast<__mmask8>((1u << shift) - 1),
                          _mm512_permutex2var_pd(carry, index, carry));
  }
  rows.carried = false;
}
}  // namespace lanes_avx512
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx2")
namespace lanes_avx2 {
namespace {
// Two halves stored at p + at and p + at + 4: for the 64-byte memcpy GCC added `at` to each of the 120 row pointers
// (an add per entry, 117 a block, ~15 per pair) before its two stores; these take the indexed address form. With
// polytope_lanes()' columns, the PolytopeLanes block went 1666 -> 1371 instructions (callgrind AVX2: 208 -> 171 a
// hull pair), the smooth ellipsoid block 1705 -> 1567.
inline __attribute__((always_inline)) void store_lanes(double* p, std::size_t at, const V8& v) {
  _mm256_storeu_pd(p + at, __m256d{v[0], v[1], v[2], v[3]});
  _mm256_storeu_pd(p + at + 4, __m256d{v[4], v[5], v[6], v[7]});
}
inline __attribute__((always_inline)) V8 sqrt_lanes(const V8& x) {
  const __m256d lo = _mm256_sqrt_pd(__m256d{x[0], x[1], x[2], x[3]});
  const __m256d hi = _mm256_sqrt_pd(__m256d{x[4], x[5], x[6], x[7]});
  return V8{lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
}
inline __attribute__((always_inline)) V8 select_positive(const V8& z, const V8& a, const V8& b) {
  const auto half = [](const V8& v, int h) { return __m256d{v[4 * h], v[4 * h + 1], v[4 * h + 2], v[4 * h + 3]}; };
  const __m256d zero = _mm256_setzero_pd();
  const __m256d lo = _mm256_blendv_pd(half(b, 0), half(a, 0), _mm256_cmp_pd(half(z, 0), zero, _CMP_GT_OQ));
  const __m256d hi = _mm256_blendv_pd(half(b, 1), half(a, 1), _mm256_cmp_pd(half(z, 1), zero, _CMP_GT_OQ));
  return V8{lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
}
}  // namespace
#include "derivative_lanes.inl"
namespace {
// A whole block to columns 0 .. kLanes - 1 of out[e] + at.
template <bool kNormalB, bool kCurved, bool kGiven>
void smooth_to(const SmoothLanes& s, double* const* out, std::size_t at) {
  smooth_block<V8, kNormalB, kCurved, kGiven>(s, [out, at](int e, const V8& v) { store_lanes(out[e], at, v); });
}
void polytope_to(const PolytopeLanes& lanes, double* const* out, std::size_t at) {
  polytope_block<V8>(lanes, [out, at](int e, const V8& v) { store_lanes(out[e], at, v); });
}
}  // namespace
}  // namespace lanes_avx2
#pragma GCC pop_options

void flush_stream_carry(StreamRows& rows, double* const* out, std::size_t at) {
  lanes_avx512::flush_stream_carry(rows, out, at);
}

// Separated pairs without flats (the smooth common case, every ellipsoid pair): M0 = sd I + H_a + H_b >= sd I is
// symmetric positive definite, so K is its explicit inverse (cofactors over the determinant, which is >= sd^3 > 0).
// Only the twist of a is solved, y = K F_a = [K, K Fa_w] (Fa_w = H_a [n]x - [x_a]x), and
//   dx_b/dxi_a = H_b y,   dx_a/dxi_a = dx_b/dxi_a + sd y   (dz = -sd y; equal to F_a - H_a y since H_a K + H_b K =
//   I - sd K),   dn/dxi_a = -(I - n n^T) y;
// the twist of b by the rigid-motion identity (as write_from_twist_a()); the lanes' arithmetic is in
// derivative_lanes.inl. Here: which set's lanes run a block (the wide ones only for a whole block on AVX2 / AVX-512).
void SmoothLanes::solve(double* const* out, bool normal_b_only, InstructionSet isa, std::size_t at,
                        StreamRows* stream) const {
  if (normal_b_only) {
    if (!curved) solve_lanes<true, false, true>(out, isa, at, stream);
    else if (given) solve_lanes<true, true, true>(out, isa, at, stream);
    else solve_lanes<true, true, false>(out, isa, at, stream);
  } else {
    if (!curved) solve_lanes<false, false, true>(out, isa, at, stream);
    else if (given) solve_lanes<false, true, true>(out, isa, at, stream);
    else solve_lanes<false, true, false>(out, isa, at, stream);
  }
}

template <bool kNormalB, bool kCurved, bool kGiven>
void SmoothLanes::solve_lanes(double* const* out, InstructionSet isa, std::size_t at, StreamRows* stream) const {
  if (isa == InstructionSet::avx512 && in_order(count, column))
    return lanes_avx512::smooth_to<kNormalB, kCurved, kGiven>(*this, count, stream, out, at);
  if (isa == InstructionSet::avx2 && whole_block<kLanes>(count, column))
    return lanes_avx2::smooth_to<kNormalB, kCurved, kGiven>(*this, out, at);
  run_lanes<kLanes>(count, column, out, at, [&](std::size_t l, const auto& put) {
    lanes_base::smooth_lanes<kNormalB, kCurved, kGiven, V>(*this, l, put);
  });
}


void PolytopeLanes::solve(double* const* out, InstructionSet isa, std::size_t at, StreamRows* stream) const {
  if (isa == InstructionSet::avx512 && in_order(count, column))
    return lanes_avx512::polytope_to(*this, count, stream, out, at);
  if (isa == InstructionSet::avx2 && whole_block<kLanes>(count, column))
    return lanes_avx2::polytope_to(*this, out, at);
  run_lanes<kLanes>(count, column, out, at,
                    [&](std::size_t l, const auto& put) { lanes_base::polytope_lanes<V>(*this, l, put); });
}


std::size_t SmoothLanes::take_lane(std::size_t col, const PairGeometry& g) {
  const std::size_t l = count++;
  column[l] = col;
  sd[l] = g.distance;
  for (int i = 0; i < 3; ++i) n[i][l] = g.normal(i), xa[i][l] = g.witness_a(i), xb[i][l] = g.witness_b(i);
  return l;
}

void SmoothLanes::zero_given() {
  // Every lane (those after l are written when added): fixed-size vector stores, where zeroing lanes 0..l became
  // 18 memset calls (~27 instructions per pair with a given H, callgrind).
  for (int e = 0; e < 9; ++e)
    for (std::size_t k = 0; k < kLanes; ++k) a.H0[e][k] = b.H0[e][k] = 0.0;
}

void SmoothLanes::flat_side(Side& s, std::size_t l) {
  for (int k = 0; k < 4; ++k) s.q[k][l] = 0.0;
  for (int i = 0; i < 3; ++i) s.radii2[i][l] = 0.0;
  s.round[l] = 0.0;
}

void SmoothLanes::add(std::size_t col, const PairGeometry& g, const CurvedSide* curved_a,
                      const CurvedSide* curved_b) {
  const std::size_t l = take_lane(col, g);
  const auto side = [&](Side& s, const CurvedSide* c, const Eigen::Matrix3d& H) {
    if (c) {
      if (given)
        for (int e = 0; e < 9; ++e) s.H0[e][l] = 0.0;
      for (int k = 0; k < 4; ++k) s.q[k][l] = c->q[k];
      for (int i = 0; i < 3; ++i) s.radii2[i][l] = c->radii2(i);
      s.round[l] = c->round;
      curved = true;
      return;
    }
    if (!given) {  // the lanes so far (this lane's other side included) have curved sides without H0
      zero_given();
      given = true;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s.H0[3 * i + j][l] = H(i, j);
    flat_side(s, l);
  };
  side(a, curved_a, g.H_a);
  side(b, curved_b, g.H_b);
}

void SmoothLanes::add_given(std::size_t col, const PairGeometry& g) {
  const std::size_t l = take_lane(col, g);
  if (!given && l > 0) zero_given();  // the lanes before have curved sides without H0
  given = true;
  flat_side(a, l);
  flat_side(b, l);
}

namespace {

// Polytopes without inflation (H_a = H_b = 0) separated, with up to two independent flats (vertex-vertex,
// vertex-face, vertex-edge, edge-edge: the hull pairs): the saddle-point system has M0 = sd I, so with P the projector on the
// flats' span (in the tangent plane) its solution for the twist of a is y = (I - P) F_a / sd + G, G the
// constraint part in the flats' span (C^T G = c), and C mu = F_a - sd y. Closed forms, per case:
//   a has no flats (a vertex against b's edge or face): G = 0, dx_a = F_a (rigid), dx_b = dx_a - sd y = P F_a;
//   b has none: G = [0, P [n]x], dx_b = 0, dx_a = sd y;
//   edge A of a against edge B of b: G = [0, B' (A x n)^T / (A . B')] (B' = n x B, so B^T G = 0 and
//   A^T G = A^T [0, [n]x]), dx_b = B (A'^T (F_a - sd y)) / (B . A') (the B part of C mu, A' = n x A),
//   dx_a = dx_b + sd y;
// and dn = -(I - n n^T) y. The general elimination below (Gram-Schmidt, an eigenvalue test, two 3x6 solves)
// cost ~2500 instructions per hull pair. Returns false (the general path decides) for dependent flats.
void write_polytope(const PairGeometry& g, const Mat36& y, const Mat36& wa, const Mat36& wb, double* s,
                    std::size_t st);

bool polytope_jacobians(const PairGeometry& g, double* s, std::size_t st) {
  const int ka = g.flats_a, kb = g.flats_b, k = ka + kb;
  const double sd = g.distance;
  if (k > 2 || !(sd > 1e-9 * g.scale) || !g.H_a.isZero(0.0) || !g.H_b.isZero(0.0)) return false;
  const Eigen::Vector3d& n = g.normal;
  Mat36 F;
  F << Eigen::Matrix3d::Identity(), -skew(g.witness_a);
  Mat36 y, wa, wb;
  if (k == 0) {  // vertex against vertex: both points move rigidly, the normal turns (y = F_a / sd)
    y = F / sd;
    wa = F;
    wb.setZero();
    return write_polytope(g, y, wa, wb, s, st), true;
  }
  Eigen::Vector3d c[2];
  for (int j = 0; j < ka; ++j) c[j] = g.flat_a.col(j);
  for (int j = 0; j < kb; ++j) c[ka + j] = g.flat_b.col(j);
  const Eigen::Vector3d q0 = c[0].normalized();
  Eigen::Matrix3d P = q0 * q0.transpose();
  if (k == 2) {
    const Eigen::Vector3d r = c[1] - q0.dot(c[1]) * q0;
    if (!(r.norm() > 1e-6)) return false;  // the general path's independence test (its columns are scale * flat)
    const Eigen::Vector3d q1 = r.normalized();
    P += q1 * q1.transpose();
  }
  y = ((Eigen::Matrix3d::Identity() - P) * F) / sd;
  if (ka == 0) {
    wa = F;
    wb = F - sd * y;
  } else if (kb == 0) {
    y.rightCols<3>() += P * skew(n);
    wb.setZero();
    wa = sd * y;
  } else {
    const Eigen::Vector3d& A = c[0];
    const Eigen::Vector3d& B = c[1];
    const Eigen::Vector3d A_perp = n.cross(A), B_perp = n.cross(B);
    y.rightCols<3>() += B_perp * (A.cross(n).transpose() / A.dot(B_perp));
    wb = B * ((A_perp.transpose() * (F - sd * y)) / B.dot(A_perp));
    wa = wb + sd * y;
  }
  write_polytope(g, y, wa, wb, s, st);
  return true;
}

void write_polytope(const PairGeometry& g, const Mat36& y, const Mat36& wa, const Mat36& wb, double* s,
                    std::size_t st) {
  const Eigen::Vector3d& n = g.normal;
  const Mat36 dn = n * (n.transpose() * y) - y;
  double n_[3] = {n.x(), n.y(), n.z()}, xa[3], xb[3], wa_[3][6], wb_[3][6], dn_[3][6];
  for (int i = 0; i < 3; ++i) {
    xa[i] = g.witness_a(i);
    xb[i] = g.witness_b(i);
    for (int j = 0; j < 6; ++j) wa_[i][j] = wa(i, j), wb_[i][j] = wb(i, j), dn_[i][j] = dn(i, j);
  }
  write_from_twist_a(n_, xa, xb, wa_, wb_, dn_, s, st);
}

}  // namespace

void write_jacobians(const PairJacobians& J, double* s, std::size_t stride) {
  for (int k = 0; k < 6; ++k) {
    s[(store_at::distance_a + k) * stride] = J.distance_a(k);
    s[(store_at::distance_b + k) * stride] = J.distance_b(k);
  }
  const std::pair<int, const Mat36*> blocks[] = {
      {store_at::witness_a_a, &J.witness_a_a}, {store_at::witness_a_b, &J.witness_a_b},
      {store_at::witness_b_a, &J.witness_b_a}, {store_at::witness_b_b, &J.witness_b_b},
      {store_at::normal_a, &J.normal_a},       {store_at::normal_b, &J.normal_b}};
  for (const auto& [e0, m] : blocks)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 6; ++c) s[(e0 + 6 * r + c) * stride] = (*m)(r, c);
}

IftFlags implicit_jacobians(const PairGeometry& g, double* slot, std::size_t stride) {
  if (polytope_jacobians(g, slot, stride)) return {};
  if (smooth_pair(g)) {
    SmoothLanes lanes{};  // one lane; differentiate_results() batches its smooth pairs through StoreBlock instead
    lanes.add(0, g);
    double out[StoreEntries][SmoothLanes::kLanes] = {};
    double* rows[StoreEntries];
    for (int e = 0; e < StoreEntries; ++e) rows[e] = out[e];
    lanes.solve(rows);
    for (int e = 0; e < StoreEntries; ++e) slot[e * stride] = out[e][0];
    return {};
  }
  const PairJacobians J = constrained_jacobians(g);
  write_jacobians(J, slot, stride);
  return {J.singular, J.dependent};
}

namespace {

// The general case: flats, touching or penetrating pairs.
PairJacobians constrained_jacobians(const PairGeometry& g) {
  PairJacobians J;
  distance_gradients(g, J.distance_a, J.distance_b);
  const Eigen::Vector3d& n = g.normal;
  const int ka = g.flats_a, kb = g.flats_b, k = ka + kb;
  const Eigen::Matrix3d M0 = g.distance * Eigen::Matrix3d::Identity() + g.H_a + g.H_b;
  if (k > 3) {  // four flat directions in 3-D are dependent
    J.dependent = true;
    set_nan(J);
    return J;
  }
  // The constraint columns are scaled to lengths (scale * flat) so that every block of the system is a length and
  // one threshold fits all of it; the multipliers come out divided by the scale and are used as C mu.
  Eigen::Vector3d C[3];
  for (int j = 0; j < ka; ++j) C[j] = g.scale * g.flat_a.col(j);
  for (int j = 0; j < kb; ++j) C[ka + j] = g.scale * g.flat_b.col(j);
  // Saddle-point system [M0 C; C^T 0] [y; mu] = [F; c], solved by eliminating the constraints in fixed sizes (a
  // dynamically sized eigendecomposition of it cost ~5x the rest of the pair): C = Q1 Rc (Gram-Schmidt), Q = [Q1,
  // Q2] orthonormal; C^T y = c fixes Q1^T y = Rc^-T c, the Q2 rows of the first block give
  // Q2^T M0 Q2 (Q2^T y) = Q2^T (F - M0 Q1 Q1^T y), and Rc mu = Q1^T (F - M0 y).
  Eigen::Matrix3d Q, Rc = Eigen::Matrix3d::Zero();
  for (int j = 0; j < k; ++j) {
    Eigen::Vector3d q = C[j];
    for (int i = 0; i < j; ++i) {
      Rc(i, j) = Q.col(i).dot(q);
      q -= Rc(i, j) * Q.col(i);
    }
    Rc(j, j) = q.norm();
    // Unit flats are independent when what is left of one after removing the others is O(1) (the diagonal of Rc
    // bounds the smallest singular value of C from above, within a factor sqrt(3) from below); below 1e-6 two
    // flats are parallel to within a micro-radian, as close to a face-face contact as the witness points'
    // accuracy can tell.
    if (!(Rc(j, j) > 1e-6 * g.scale)) {
      J.dependent = true;
      set_nan(J);
      return J;
    }
    Q.col(j) = q / Rc(j, j);
  }
  if (k == 0) Q.setIdentity();
  if (k == 1) Q.col(1) = Q.col(0).unitOrthogonal();
  if (k == 1 || k == 2) Q.col(2) = Q.col(0).cross(Q.col(1));
  // In w = Q^T y the system is T w = [Rc^-T c; Q2^T F] with T = [I_k 0; Q2^T M0 Q1, Q2^T M0 Q2]: det T is that of
  // the reduced matrix Q2^T M0 Q2, singular (touching without curvature, some penetrations) when it has an
  // eigenvalue within 1e-9 of the problem's length scale: its inverse would magnify the witness points' own error
  // (~1e-8 of that scale at the default GJK tolerance) beyond any meaning.
  const Eigen::Matrix3d QMQ = Q.transpose() * (0.5 * (M0 + M0.transpose())) * Q;
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();  // the reduced matrix, the constraint block set to the scale
  E.topLeftCorner(k, k).diagonal().setConstant(g.scale);
  E.bottomRightCorner(3 - k, 3 - k) = QMQ.bottomRightCorner(3 - k, 3 - k);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(E, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues().cwiseAbs().minCoeff() > 1e-9 * g.scale)) {
    J.singular = true;
    set_nan(J);
    return J;
  }
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T.bottomRows(3 - k) = QMQ.bottomRows(3 - k);
  const Eigen::Matrix3d T_inverse = T.inverse();
  const Mat36 rotation_of_n = (Mat36() << Eigen::Matrix3d::Zero(), skew(n)).finished();  // [0, [n]x]
  const Mat36 F_a = (Mat36() << Eigen::Matrix3d::Identity(), -skew(g.witness_a) + g.H_a * skew(n)).finished();
  const Mat36 F_b = (Mat36() << -Eigen::Matrix3d::Identity(), skew(g.witness_b) + g.H_b * skew(n)).finished();
  // Solves for one shape's twist (its constraint rows are c = C_j^T [0, [n]x], the other shape's are 0); returns
  // y, A mu_a and B mu_b.
  const auto solve = [&](const Mat36& F, bool twist_of_a, Mat36& y, Mat36& A_mu, Mat36& B_mu) {
    Mat36 rhs = Q.transpose() * F;  // rows k.. are Q2^T F; rows ..k become Rc^-T c (forward substitution)
    for (int j = 0; j < k; ++j) {
      const bool own = twist_of_a ? j < ka : j >= ka;
      Row6 c = own ? Row6(C[j].transpose() * rotation_of_n) : Row6::Zero();
      for (int i = 0; i < j; ++i) c -= Rc(i, j) * rhs.row(i);
      rhs.row(j) = c / Rc(j, j);
    }
    y = Q * (T_inverse * rhs);
    Mat36 r = Q.transpose() * (F - M0 * y);  // rows ..k: Rc mu (back substitution)
    Mat36 mu = Mat36::Zero();
    for (int j = k - 1; j >= 0; --j) {
      Row6 v = r.row(j);
      for (int i = j + 1; i < k; ++i) v -= Rc(j, i) * mu.row(i);
      mu.row(j) = v / Rc(j, j);
    }
    A_mu.setZero();
    B_mu.setZero();
    for (int j = 0; j < ka; ++j) A_mu += C[j] * mu.row(j);
    for (int j = ka; j < k; ++j) B_mu += C[j] * mu.row(j);
  };
  const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
  Mat36 y, A_mu, B_mu;
  solve(F_a, true, y, A_mu, B_mu);
  J.witness_a_a = F_a - g.H_a * y - A_mu;
  J.witness_b_a = g.H_b * y + B_mu;
  J.normal_a = -tangent * y;
  solve(F_b, false, y, A_mu, B_mu);
  J.witness_a_b = -(g.H_a * y + A_mu);
  J.witness_b_b = g.H_b * y + B_mu - F_b;
  J.normal_b = -tangent * y;
  return J;
}

}  // namespace
}  // namespace batchcol::detail
