// Randomized smoothing of order 0 (Montaut et al. 2023, sec. III; the slides "Randomized smoothing" and "- 0th
// order"). The M perturbed copies ("samples") of a pair share its shapes, A's pose and B's pose up to the
// perturbation, so they do not go through collide() as new pairs (whose validation, type grouping, world poses and
// outputs per sample cost more than a warm-started sample's GJK): each sample's relative pose is built in A's frame
// straight into the SIMD GJK's sample layout (kernels::simd::build_samples, gjk_samples), its answer stays in A's
// frame, and the estimator is reduced there and mapped to the world once per pair. Each sample's GJK starts from the
// direction the analytic normal Jacobian predicts for its perturbation (first order: on curved pairs GJK then needs
// about one iteration, the start being off by O(eps^2) only); polytope pairs, whose GJK needs its simplex anyway,
// start from the unperturbed query's direction.
#include "counter_rng.hpp"
#include "derivative_pairs.hpp"
#include "instruction_set.hpp"
#include "kernel_views.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"
#include "validate.hpp"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <limits>
#include <vector>

// The vector types of derivative_finish_lanes.inl cross no call boundary between instruction sets (each set's code
// calls only its own, always inlined) and no object boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace batchcol::detail {
namespace {

/// Samples per block of a task: the block's poses, directions, noise and answers (~40 doubles per sample, ~330 KB)
/// stay in L2 between the sample generation, the GJK and the reduction. Even: blocks end on antithetic pairs.
constexpr std::size_t kBlockSamples = 1024;
/// Small M: one pair's M / 2 first samples fill a part of a register of the sample builder (M = 4: 2 of AVX2's 4
/// double lanes, 2 of AVX-512's 8), whose draws and poses cost the same whatever its lanes hold; so up to
/// kGroupEvens / (M / 2) pairs are built together (build_group()). kGroupEvens: AVX-512's lanes.
constexpr std::size_t kGroupEvens = 8;

struct Noise {
  double translation = 0.0, rotation = 0.0;  // standard deviations: metres, radians
};

Noise noise_of(const ShapeTable& shapes, std::uint32_t b, const DerivativeOptions& o) {
  const double r = b < shapes.size() ? ShapeTableAccess::bounding_radii(shapes)[b] : 1.0;
  if (!std::isfinite(r) || !(r > 0.0)) return {0.0, 0.0};  // halfspace b: the pair is not differentiated
  return o.noise_scale == NoiseScale::relative ? Noise{o.noise * r, o.noise} : Noise{o.noise, o.noise / r};
}

/// A shape with curvature somewhere (a round part or an inflation): the samples' GJK gains from a predicted start.
bool curved(const ShapeTable& shapes, std::uint32_t s) {
  if (s >= shapes.size()) return false;
  const Shape& shape = shapes[s];
  return shape.inflation > 0.0 || (shape.type != ShapeType::box && shape.type != ShapeType::convex &&
                                   shape.type != ShapeType::triangle && shape.type != ShapeType::halfspace);
}

/// What the samples of pair i share: A's pose (Ra row-major, ta) for the mapping to the world, the unperturbed answer
/// g0 in A's frame (distance, witness points, normal), the noise scales, and `samples`, what build_samples() reads:
/// B's pose in A's frame, the first GJK direction without perturbation and its first-order change P z.
struct PairPlan {
  std::size_t i = 0;
  bool ok = false;  // false: no nominal witness, or b has no finite size (store_nothing)
  double Ra[3][3], ta[3];
  double g0[10];
  Noise s;
  ShapeType type_a = ShapeType::sphere, type_b = ShapeType::sphere;
  bool wide = false;  // the type pair runs through gjk_samples
  kernels::simd::SamplePlan samples;
  kernels::simd::WarmSimplex warm;  // convex-convex pairs: the samples' starting simplex (warm_simplex())
};

struct Context {
  const ShapeTable& shapes;
  const PairBatch& batch;
  const PairResults& results;
  const DerivativeOptions& o;
  QueryOptions query;  // solver resolved
  InstructionSet isa;
  const DerivativeResults* predictor;  // analytic derivatives of the pairs with a curved side, or null
  kernels::simd::PairView view;
};

bool wide_type_pair(ShapeType a, ShapeType b, const QueryOptions& q) {
  const auto plain = [](ShapeType t) { return t != ShapeType::triangle && t != ShapeType::halfspace; };
  return plain(a) && plain(b) && !kernels::may_have_closed_form(a, b, q);
}

/// warm_simplex()'s feature tolerance, relative to the pair's size (the hulls' bounding radii).
constexpr double kFeatureTolerance = 1e-9;

/// The nominal answer's simplex of a hull pair (A's frame: B's vertices under R0, t0), for the samples' warm start:
/// the vertices of A's hull on its supporting plane at the nominal normal n (A towards B) and B's on its own, within
/// kFeatureTolerance of the support value, combined as GJK's simplex holds them: vertex-vertex, vertex-edge, vertex-
/// face (one pair per vertex of the larger feature), or edge-edge, where the closest point lies in one of the two
/// triangles of the parallelogram of the four vertex pairs (chosen by the witness points' edge parameters s on A's
/// edge and u on B's: s >= u the triangle (a1 b1, a2 b1, a2 b2), else (a1 b1, a1 b2, a2 b2)). Other features
/// (a quad face, ties) get no warm start. A wrong guess costs iterations only: the samples' GJK certifies its
/// answer by the duality gap from whatever simplex it starts.
kernels::simd::WarmSimplex warm_simplex(const HullView& ha, const HullView& hb, const kernels::simd::SamplePlan& sp,
                                        const double (&g0)[10], double size) {
  kernels::simd::WarmSimplex ws;
  const double n[3] = {g0[7], g0[8], g0[9]};
  // Relative to the pair's size: far above the nominal normal's rounding (~1e-16 |x| on an exact feature), far
  // below the gaps between a random hull's support values.
  const double tol = kFeatureTolerance * size;
  const auto dot = [](const double* p, const double* q) { return (p[0] * q[0] + p[1] * q[1]) + p[2] * q[2]; };
  const auto a_at = [&](std::uint32_t i, double* p) { for (int e = 0; e < 3; ++e) p[e] = ha.vertices[3 * i + e]; };
  const auto b_at = [&](std::uint32_t j, double* p) {
    const double* v = hb.vertices + 3 * j;
    for (int e = 0; e < 3; ++e) p[e] = ((sp.R0[3 * e] * v[0] + sp.R0[3 * e + 1] * v[1]) + sp.R0[3 * e + 2] * v[2]) + sp.t0[e];
  };
  // A's vertices maximise <v, n>; B's minimise <R0 v + t0, n> = <v, R0^T n> + const, so B's are scored in its own
  // frame against m = -R0^T n (the constant does not change which are within tol of the best).
  const double m[3] = {-((sp.R0[0] * n[0] + sp.R0[3] * n[1]) + sp.R0[6] * n[2]),
                       -((sp.R0[1] * n[0] + sp.R0[4] * n[1]) + sp.R0[7] * n[2]),
                       -((sp.R0[2] * n[0] + sp.R0[5] * n[1]) + sp.R0[8] * n[2])};
  // Up to 4 vertices within tol of the best (4: too many for a warm simplex).
  const auto feature = [&](const HullView& h, const double* d, std::uint32_t* f) {
    double score[kernels::kHillClimbMinVertices];
    double best = -std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < h.vertex_count; ++i) {
      score[i] = dot(h.vertices + 3 * i, d);
      best = std::max(best, score[i]);
    }
    std::uint32_t k = 0;
    for (std::uint32_t i = 0; i < h.vertex_count && k < 4; ++i)
      if (score[i] >= best - tol) f[k++] = i;
    return k;
  };
  std::uint32_t fa[4], fb[4];
  const std::uint32_t ka = feature(ha, n, fa);
  const std::uint32_t kb = feature(hb, m, fb);
  if (ka == 1 && kb <= 3) {
    ws.count = kb;
    for (std::uint32_t q = 0; q < kb; ++q) ws.a[q] = fa[0], ws.b[q] = fb[q];
  } else if (kb == 1 && ka <= 3) {
    ws.count = ka;
    for (std::uint32_t q = 0; q < ka; ++q) ws.a[q] = fa[q], ws.b[q] = fb[0];
  } else if (ka == 2 && kb == 2) {
    double a1[3], a2[3], b1[3], b2[3], ea[3], eb[3], da[3], db[3];
    a_at(fa[0], a1), a_at(fa[1], a2), b_at(fb[0], b1), b_at(fb[1], b2);
    for (int e = 0; e < 3; ++e) {
      ea[e] = a2[e] - a1[e], eb[e] = b2[e] - b1[e];
      da[e] = g0[1 + e] - a1[e], db[e] = g0[4 + e] - b1[e];
    }
    const double s = dot(da, ea) / dot(ea, ea), u = dot(db, eb) / dot(eb, eb);
    if (!std::isfinite(s) || !std::isfinite(u)) return ws;
    ws.count = 3;
    ws.a[0] = fa[0], ws.b[0] = fb[0];
    ws.a[2] = fa[1], ws.b[2] = fb[1];
    if (s >= u) ws.a[1] = fa[1], ws.b[1] = fb[0];
    else ws.a[1] = fa[0], ws.b[1] = fb[1];
  }
  return ws;
}

/// Ra^T v, in the order of Eigen's R_a.transpose() * v: (Ra(0,r) v0 + Ra(1,r) v1) + Ra(2,r) v2.
inline void rotate_back(const double (&Ra)[3][3], const double* v, double* out) {
  for (int r = 0; r < 3; ++r) out[r] = (Ra[0][r] * v[0] + Ra[1][r] * v[1]) + Ra[2][r] * v[2];
}

/// Plans pair i. Plain loops in the operation order of the Eigen expressions they replace (R_a.transpose() * R_b,
/// R_a.transpose() * v, s * (R_a.transpose() * X * R_a): Eigen moves the scalar onto R_a.transpose() and sums the
/// outer product's row 2 as a0 + (a1 + a2); each order found by a bitwise comparison against Eigen on 20000 random
/// poses and Jacobians): the same bits, without the 3x3 temporaries, the PairPlan copies of R, t and P and
/// Eigen's ~410 instructions for P.
void plan_pair(const Context& c, std::size_t i, PairPlan& p) {
  p.i = i;
  PairGeometry g;
  Eigen::Matrix3d R_a, R_b;
  p.ok = nominal_geometry(c.shapes, c.batch, c.results, i, g, R_a, R_b);
  if (!p.ok) return;
  p.s = noise_of(c.shapes, c.batch.shape_b[i], c.o);
  if (!(p.s.translation > 0.0)) {
    p.ok = false;
    return;
  }
  kernels::simd::SamplePlan& sp = p.samples;
  double(&Ra)[3][3] = p.Ra;
  double Rb[3][3];
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) Ra[r][q] = R_a(r, q), Rb[r][q] = R_b(r, q);
  const double ta[3] = {c.batch.translation_a.x[i], c.batch.translation_a.y[i], c.batch.translation_a.z[i]};
  const double tb[3] = {c.batch.translation_b.x[i], c.batch.translation_b.y[i], c.batch.translation_b.z[i]};
  for (int r = 0; r < 3; ++r) {
    p.ta[r] = ta[r];
    for (int q = 0; q < 3; ++q) sp.R0[3 * r + q] = (Ra[0][r] * Rb[0][q] + Ra[1][r] * Rb[1][q]) + Ra[2][r] * Rb[2][q];
  }
  const double dt[3] = {tb[0] - ta[0], tb[1] - ta[1], tb[2] - ta[2]};
  rotate_back(Ra, dt, sp.t0);
  const double wa[3] = {g.witness_a.x() - ta[0], g.witness_a.y() - ta[1], g.witness_a.z() - ta[2]};
  const double wb[3] = {g.witness_b.x() - ta[0], g.witness_b.y() - ta[1], g.witness_b.z() - ta[2]};
  p.g0[0] = g.distance;
  rotate_back(Ra, wa, p.g0 + 1);
  rotate_back(Ra, wb, p.g0 + 4);
  rotate_back(Ra, g.normal.data(), p.g0 + 7);
  double d[3] = {-g.normal.x(), -g.normal.y(), -g.normal.z()};
  if (c.results.direction.size() == c.batch.size())
    d[0] = c.results.direction.x[i], d[1] = c.results.direction.y[i], d[2] = c.results.direction.z[i];
  rotate_back(Ra, d, sp.first);
  for (int r = 0; r < 3; ++r) sp.n0[r] = p.g0[7 + r];
  const auto& types = ShapeTableAccess::types(c.shapes);
  p.type_a = types[c.batch.shape_a[i]];
  p.type_b = types[c.batch.shape_b[i]];
  p.wide = wide_type_pair(p.type_a, p.type_b, c.query);
  sp.predict = false;
  if (c.predictor && (c.predictor->status[i] == DerivativeStatus::smooth ||
                      c.predictor->status[i] == DerivativeStatus::zero_curvature)) {
    // A sample moves b about its own origin by v_n = s_t Ra z_v and w = s_w Ra z_w (z in A's frame): the world
    // twist (v_n + t_b x w, w); the normal moves by J_n of that, taken back to A's frame:
    // P = [s_t Ra^T Jv Ra, s_w Ra^T (Jv [t_b]x + Jw) Ra].
    // Read in place (entry (r, c) at data[(6 r + c) n + i]): Mat36Array::operator[]'s out-of-line copy cost 63
    // instructions a pair (callgrind AVX2, ellipsoids M = 16).
    const double* Jd = c.predictor->normal_wrt_b.data.data();
    const std::size_t jn = c.predictor->normal_wrt_b.size();
    const auto J = [&](int r, int q) { return Jd[(6 * r + q) * jn + i]; };
    const double S[3][3] = {{0.0, -tb[2], tb[1]}, {tb[2], 0.0, -tb[0]}, {-tb[1], tb[0], 0.0}};  // skew(t_b)
    double X[2][3][3];  // Jv, Jv [t_b]x + Jw
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) {
        X[0][r][q] = J(r, q);
        X[1][r][q] = ((J(r, 0) * S[0][q] + J(r, 1) * S[1][q]) + J(r, 2) * S[2][q]) + J(r, 3 + q);
      }
    // Two columns per SSE2 register (k, q = 0, 1; column 2 alone): the same operations per entry.
    using V2 = double __attribute__((vector_size(16)));
    const auto ld = [](const double* p) { V2 v; std::memcpy(&v, p, sizeof v); return v; };
    const V2 ra01[3] = {ld(Ra[0]), ld(Ra[1]), ld(Ra[2])};
    V2 bad = {0.0, 0.0};  // x - x: 0 for finite x, NaN otherwise
    for (int h = 0; h < 2; ++h) {
      const double s = h == 0 ? p.s.translation : p.s.rotation;
      double sR[3][3];  // s Ra
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) sR[r][q] = s * Ra[r][q];
      const V2 x01[3] = {ld(X[h][0]), ld(X[h][1]), ld(X[h][2])};
      for (int r = 0; r < 3; ++r) {  // row r of (s Ra)^T X, then of that times Ra
        const V2 l01 = (x01[0] * sR[0][r] + x01[1] * sR[1][r]) + x01[2] * sR[2][r];
        const double l2 = (sR[0][r] * X[h][0][2] + sR[1][r] * X[h][1][2]) + sR[2][r] * X[h][2][2];
        const double l0 = l01[0], l1 = l01[1];
        const V2 a0 = ra01[0] * l0, a1 = ra01[1] * l1, a2 = ra01[2] * l2;
        const V2 v01 = r < 2 ? (a0 + a1) + a2 : a0 + (a1 + a2);
        const double b0 = l0 * Ra[0][2], b1 = l1 * Ra[1][2], b2 = l2 * Ra[2][2];
        const double v2 = r < 2 ? (b0 + b1) + b2 : b0 + (b1 + b2);
        double* out = sp.P + 6 * r + 3 * h;
        out[0] = v01[0], out[1] = v01[1], out[2] = v2;
        bad += (v01 - v01) + (v2 - v2);
      }
    }
    const bool finite = bad[0] + bad[1] == 0.0;
    sp.predict = finite;
  }
  if (!sp.predict) std::fill_n(sp.P, 18, 0.0);
  p.warm = {};
  if (p.wide && p.type_a == ShapeType::convex && p.type_b == ShapeType::convex) {
    const HullView& ha = c.view.shape_hull[c.batch.shape_a[i]];
    const HullView& hb = c.view.shape_hull[c.batch.shape_b[i]];
    // Small hulls only: the feature scan reads every vertex (large hulls' samples climb from a start cell).
    if (ha.vertex_count < kernels::kHillClimbMinVertices && hb.vertex_count < kernels::kHillClimbMinVertices)
      p.warm = warm_simplex(ha, hb, sp, p.g0, c.view.bounding_radii[c.batch.shape_a[i]] +
                                                   c.view.bounding_radii[c.batch.shape_b[i]]);
  }
  sp.key = splitmix64(splitmix64(c.o.seed) ^ i);  // the (seed, pair) key of counter_rng.hpp's sample_noise()
  sp.translation = p.s.translation;
  sp.rotation = p.s.rotation;
}

/// One block's samples, structure of arrays (the kernel's layout), and their answers, one row of kRow per sample
/// (distance, witness a, witness b, normal, two zeros: the reduction reads a sample's values as whole registers).
struct Block {
  enum Array { kR = 0, kT = 9, kDir = 12, kZ = 15, kArrays = 21 };
  static constexpr std::size_t kRow = 12;
  std::size_t capacity = 0, count = 0;
  std::vector<double> data, values;
  std::vector<std::uint32_t> shape_a, shape_b, fallback;
  std::vector<const kernels::simd::WarmSimplex*> warm;  // per sample: its pair's simplex (convex-convex), or null
  std::vector<Status> status;
  double* at(int array) { return data.data() + static_cast<std::size_t>(array) * capacity; }
  double* row(std::size_t k) { return values.data() + kRow * k; }
  void reserve(std::size_t n) {
    capacity = n;
    data.resize(kArrays * n);
    values.assign(kRow * n, 0.0);  // the padding stays 0
    shape_a.resize(n);
    shape_b.resize(n);
    warm.resize(n);
    fallback.resize(n);
    status.resize(n);
  }
};

/// One pair's samples in the block: plan, its samples [first, first + count) of the block, the first being its
/// sample j0.
struct Span {
  std::size_t plan, first, count, j0;
};

/// The builder's output arrays for samples written from block slot `slot`: the first samples of the antithetic
/// pairs at slot .., their copies `evens` slots after them.
void sample_arrays(Block& b, std::size_t slot, std::size_t evens, kernels::simd::SampleArrays& even,
                   kernels::simd::SampleArrays& odd) {
  for (int e = 0; e < 9; ++e) even.R[e] = b.at(Block::kR + e) + slot, odd.R[e] = even.R[e] + evens;
  for (int e = 0; e < 3; ++e) {
    even.t[e] = b.at(Block::kT + e) + slot, odd.t[e] = even.t[e] + evens;
    even.direction[e] = b.at(Block::kDir + e) + slot, odd.direction[e] = even.direction[e] + evens;
  }
  for (int e = 0; e < 6; ++e) even.z[e] = b.at(Block::kZ + e) + slot, odd.z[e] = even.z[e] + evens;
}

/// Writes samples j0 .. j0 + count of plan p (j0 even) at block slot `slot`: the first samples of the antithetic
/// pairs (2k: z = sample_noise(key of (seed, pair), k) in A's frame) at slot .. slot + evens, their copies (2k+1: -z,
/// the transposed rotation) after them, so that build_samples() writes whole registers.
void build(const Context& c, const PairPlan& p, std::size_t j0, std::size_t count, Block& b, std::size_t slot) {
  const std::size_t evens = (count + 1) / 2, odds = count / 2;
  kernels::simd::SampleArrays even, odd;
  sample_arrays(b, slot, evens, even, odd);
  const kernels::simd::SamplePlan* plans[] = {&p.samples};
  kernels::simd::build_samples(c.isa, plans, 1, count, j0 / 2, evens, odds, even, odd);
  std::fill_n(b.shape_a.data() + slot, count, c.batch.shape_a[p.i]);
  std::fill_n(b.shape_b.data() + slot, count, c.batch.shape_b[p.i]);
}

/// All M samples (M even, M / 2 <= kGroupEvens / 2) of the n pairs group[0 .. n), pair q's at block slot
/// slot + q M as build() lays them out, from one call of the builder, whose registers then hold several pairs'
/// samples. Each sample gets the bits build() gives it.
void build_group(const Context& c, const PairPlan* const* group, std::size_t n, std::size_t M, Block& b,
                 std::size_t slot) {
  const std::size_t e = M / 2;
  kernels::simd::SampleArrays even, odd;
  sample_arrays(b, slot, e, even, odd);
  const kernels::simd::SamplePlan* plans[kGroupEvens] = {};
  for (std::size_t q = 0; q < n; ++q) plans[q] = &group[q]->samples;
  kernels::simd::build_samples(c.isa, plans, n, M, 0, e, e, even, odd);
  for (std::size_t q = 0; q < n; ++q) {
    std::fill_n(b.shape_a.data() + slot + q * M, M, c.batch.shape_a[group[q]->i]);
    std::fill_n(b.shape_b.data() + slot + q * M, M, c.batch.shape_b[group[q]->i]);
  }
}

/// The scalar path for one sample: setup, GJK, completion (closed forms, EPA, float stalls redone in double).
template <class T> void solve_sample(const Context& c, Block& b, std::size_t k) {
  const std::size_t cap = b.capacity;
  const double* R = b.at(Block::kR);
  const double* t = b.at(Block::kT);
  const double* dir = b.at(Block::kDir);
  kernels::RelativePose X;
  for (int r = 0; r < 3; ++r) {
    for (int q = 0; q < 3; ++q) X.R(r, q) = R[(3 * r + q) * cap + k];
    X.t[r] = t[r * cap + k];
  }
  const Eigen::Vector3d warm(dir[k], dir[cap + k], dir[2 * cap + k]);
  const kernels::PairOutput<T> r =
      kernels::solve_pair<T>(ShapeTableAccess::view(c.shapes, b.shape_a[k]), ShapeTableAccess::view(c.shapes, b.shape_b[k]),
                             X, warm, c.query);
  b.status[k] = r.status;
  double* v = b.row(k);
  v[0] = double(r.distance);
  for (int e = 0; e < 3; ++e) {
    v[1 + e] = double(r.witness_a[e]);
    v[4 + e] = double(r.witness_b[e]);
    v[7 + e] = double(r.normal[e]);
  }
}

template <class T> void solve_samples(const Context& c, Block& b, std::size_t first, std::size_t count, bool wide,
                                      ShapeType ta, ShapeType tb) {
  if (!wide) {
    for (std::size_t k = first; k < first + count; ++k) solve_sample<T>(c, b, k);
    return;
  }
  const std::size_t cap = b.capacity;
  kernels::simd::SampleBatch in;
  in.shape_a = b.shape_a.data() + first;
  in.shape_b = b.shape_b.data() + first;
  in.samples = count;
  in.warm = b.warm.data() + first;
  for (int e = 0; e < 9; ++e) in.R[e] = b.at(Block::kR) + e * cap + first;
  for (int e = 0; e < 3; ++e) {
    in.t[e] = b.at(Block::kT) + e * cap + first;
    in.direction[e] = b.at(Block::kDir) + e * cap + first;
  }
  kernels::simd::SampleResults out;
  out.status = b.status.data() + first;
  double* v = b.row(first);
  out.stride = Block::kRow;
  out.distance = v;
  for (int e = 0; e < 3; ++e) {
    out.witness_a[e] = v + 1 + e;
    out.witness_b[e] = v + 4 + e;
    out.normal[e] = v + 7 + e;
  }
  const std::size_t left = kernels::simd::gjk_samples<T>(c.isa, c.view, ta, tb, in, c.query, out, b.fallback.data());
  for (std::size_t f = 0; f < left; ++f) solve_sample<T>(c, b, first + b.fallback[f]);
}

using Sums = kernels::simd::SampleSums;

/// Adds samples [first, first + count) of the block (the first sample of antithetic pair e at first + e, its copy
/// at first + evens + e: build()) to the pair's sums, in the kernels' lanes: each sample's values (distance, witness
/// points, normal in A's frame) minus the unperturbed ones, times its noise z, and the values themselves; a sample
/// without a converged, finite answer adds nothing.
void accumulate(const Context& c, Block& b, std::size_t first, std::size_t count, Sums& sums) {
  const double* z[6];
  for (int f = 0; f < 6; ++f) z[f] = b.at(Block::kZ + f) + first;
  kernels::simd::accumulate_samples(c.isa, b.row(first), b.status.data() + first, z, count, (count + 1) / 2, sums);
}

/// What FinishLanes keeps of a pair for the lanes: the sums, the noise scales, A's rotation, B's position and the
/// smoothed witness points and normal in the world (x[0], x[1], x[2]), lane l of each array.
struct FinishIn {
  static constexpr std::size_t kLanes = 8;
  alignas(64) double G[6][10][kLanes];
  alignas(64) double valid[kLanes], s_t[kLanes], s_w[kLanes], Ra[9][kLanes], tb[3][kLanes], x[3][3][kLanes];
};

}  // namespace

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw")
namespace finish_avx512 {
#include "derivative_finish_lanes.inl"
}  // namespace finish_avx512
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx2")
namespace finish_avx2 {
#include "derivative_finish_lanes.inl"
}  // namespace finish_avx2
#pragma GCC pop_options
namespace finish_baseline {
#include "derivative_finish_lanes.inl"
}  // namespace finish_baseline

namespace {

/// The estimator of up to FinishIn::kLanes consecutive pairs, mapped to the world in SIMD lanes (one pair per
/// lane, derivative_finish_lanes.inl) and written straight to the output arrays, each array one whole register of
/// 8 consecutive pairs when the block is full (StoreBlock's reason: 120 arrays a power of two apart, written pair by
/// pair, share one L1 set). Pair by pair in SSE2 (the previous finish_pair()) this cost 1507 instructions per pair
/// (callgrind, AVX2 build, ellipsoids M = 4), more than a witness query's GJK loop. Flushes when a pair is not the
/// next one, when full and on destruction.
class FinishLanes {
 public:
  static constexpr std::size_t kLanes = FinishIn::kLanes;
  /// `d` is sized already (smoothed0() sizes it before the tasks start): the 120 output rows of pair 0 are taken
  /// once here, a block's at rows_[k] + first_ (entry_rows() at every flush cost 94 instructions a pair, callgrind
  /// AVX2, ellipsoids M = 16).
  FinishLanes(DerivativeResults& d, InstructionSet isa) : isa_(isa) { entry_rows(d, 0, rows_); }
  FinishLanes(const FinishLanes&) = delete;
  FinishLanes& operator=(const FinishLanes&) = delete;
  ~FinishLanes() { flush(); }
  void add(std::size_t i, const Sums& sums, const PairPlan& p, const double (&tb)[3], const double (&x)[3][3]) {
    if (count_ == kLanes || (count_ > 0 && i != first_ + count_)) flush();
    if (count_ == 0) first_ = i;
    const std::size_t l = count_++;
    for (int e = 0; e < 6; ++e)
      for (int r = 0; r < 10; ++r) in_.G[e][r][l] = sums.G[e][r];
    in_.valid[l] = double(sums.valid);
    in_.s_t[l] = p.s.translation;
    in_.s_w[l] = p.s.rotation;
    for (int r = 0; r < 3; ++r) {
      for (int q = 0; q < 3; ++q) in_.Ra[3 * r + q][l] = p.Ra[r][q], in_.x[r][q][l] = x[r][q];
      in_.tb[r][l] = tb[r];
    }
  }
  void flush() {
    if (count_ == 0) return;
    if (count_ == kLanes) {
      solve(rows_, first_);
    } else {
      alignas(64) double buffer[StoreEntries][kLanes];
      double* buffer_rows[StoreEntries];
      for (int k = 0; k < StoreEntries; ++k) buffer_rows[k] = buffer[k];
      solve(buffer_rows, 0);
      for (int k = 0; k < StoreEntries; ++k) std::copy_n(buffer[k], count_, rows_[k] + first_);
    }
    count_ = 0;
  }

 private:
  void solve(double* const* out, std::size_t at) const {
    if (isa_ == InstructionSet::avx512) finish_avx512::finish_lanes(in_, out, at);
    else if (isa_ == InstructionSet::avx2) finish_avx2::finish_lanes(in_, out, at);
    else finish_baseline::finish_lanes(in_, out, at);
  }
  InstructionSet isa_;
  double* rows_[StoreEntries];
  FinishIn in_{};  // value-initialised: lanes past count_ are computed (not written) on initialised numbers
  std::size_t first_ = 0, count_ = 0;
};

/// The estimator from the sums: the smoothed values mapped from A's frame to the world here, the derivatives
/// queued for FinishLanes. Each entry gets the operations, in their order, of the Eigen expressions the mapping
/// replaced (products summed k = 0, 1, 2 left to right, except row 2 of Ra times a 3-row block, which Eigen
/// computes after its 2-row packet as a0 + (a1 + a2); the same divisions; the rigid-motion blocks' signed zeros),
/// so the bits are those of the Eigen version.
void finish_pair(const Context& c, const PairPlan& p, const Sums& sums, StoreBlock& out, FinishLanes& lanes) {
  const std::size_t i = p.i;
  if (sums.valid == 0) return store_nothing(out, i);
  DerivativeResults& d = out.d;
  const double valid = double(sums.valid);
  double mean[10];
  for (int r = 0; r < 10; ++r) mean[r] = sums.mean[r] / valid;
  const double(&Ra)[3][3] = p.Ra;
  // Values to the world: Ra m + ta (r0 = 1, 4) or Ra m (r0 = 7).
  const auto world = [&](int r0, double* v) {
    for (int q = 0; q < 2; ++q) v[q] = (Ra[q][0] * mean[r0] + Ra[q][1] * mean[r0 + 1]) + Ra[q][2] * mean[r0 + 2];
    v[2] = Ra[2][0] * mean[r0] + (Ra[2][1] * mean[r0 + 1] + Ra[2][2] * mean[r0 + 2]);
  };
  double x[3][3];  // witness a, witness b, normal
  world(1, x[0]), world(4, x[1]), world(7, x[2]);
  for (int q = 0; q < 3; ++q) x[0][q] += p.ta[q], x[1][q] += p.ta[q];
  const double tb[3] = {c.batch.translation_b.x[i], c.batch.translation_b.y[i], c.batch.translation_b.z[i]};
  lanes.add(i, sums, p, tb, x);
  d.smoothed_distance[i] = mean[0];
  d.smoothed_witness_a.set(i, Eigen::Vector3d(x[0][0], x[0][1], x[0][2]));
  d.smoothed_witness_b.set(i, Eigen::Vector3d(x[1][0], x[1][1], x[1][2]));
  d.smoothed_normal.set(i, Eigen::Vector3d(x[2][0], x[2][1], x[2][2]));
  d.status[i] = sums.valid == c.o.samples ? DerivativeStatus::smooth : DerivativeStatus::partial_samples;
}

template <class T> void run_pairs(const Context& c, std::size_t begin, std::size_t end, DerivativeResults& d) {
  const std::size_t M = static_cast<std::size_t>(c.o.samples);
  thread_local Block block;  // reused by every task of this thread (a task never waits on TBB)
  if (block.capacity != kBlockSamples) block.reserve(kBlockSamples);
  // Reused like the block: grown per call, a block's up to kBlockSamples / 2 plans were reallocated and copied
  // ~8 times per call at M = 4.
  thread_local std::vector<PairPlan> plans;
  thread_local std::vector<Span> spans;
  // Pairs per group (build_group()); 1: each pair alone (odd M: the last antithetic pair has no copy).
  const std::size_t group = M % 2 == 0 && M / 2 <= kGroupEvens / 2 ? kGroupEvens / (M / 2) : 1;
  StoreBlock out(d);  // the pairs without an estimator (store_nothing())
  FinishLanes lanes(d, c.isa);
  Sums sums;
  std::size_t i = begin, j = 0;  // the next sample to build: sample j of pair i
  bool planned = false;          // pair i is planned, in plans[count - 1] (its samples continue in this block)
  std::size_t count = 0;         // plans in use; the vector only grows, so a pair is planned in place, not copied
  // Plans pair i in plans[count]; a pair that cannot be planned gets its empty outputs and is skipped (false).
  const auto plan_next = [&]() {
    if (count == plans.size()) plans.emplace_back();
    PairPlan& p = plans[count];
    plan_pair(c, i, p);
    if (p.ok) return true;
    store_nothing(out, i);
    ++i;
    return false;
  };
  while (i < end) {
    // Fill the block with whole antithetic pairs of samples, pair after pair; a pair left unfinished by the last
    // block keeps its plan, moved to the front.
    if (planned && count > 1) plans[0] = plans[count - 1];
    count = planned ? 1 : 0;
    spans.clear();
    std::size_t used = 0;
    while (i < end && used + 2 <= kBlockSamples) {
      if (group > 1) {
        // Up to `group` whole pairs, of any type pairs (the runs below group the spans by type pair).
        const PairPlan* members[kGroupEvens] = {};
        std::size_t n = 0;
        while (i < end && n < group && used + (n + 1) * M <= kBlockSamples) {
          if (!plan_next()) continue;
          ++count;
          ++i;
          ++n;
        }
        if (n == 0) {
          if (i < end) break;  // the block is full
          continue;
        }
        // plans may have grown: the members' addresses are taken once the group is complete.
        for (std::size_t q = 0; q < n; ++q) members[q] = &plans[count - n + q];
        build_group(c, members, n, M, block, used);
        for (std::size_t q = 0; q < n; ++q) spans.push_back({count - n + q, used + q * M, M, 0});
        used += n * M;
        continue;
      }
      if (!planned) {
        j = 0;
        if (!plan_next()) continue;
        ++count;
        planned = true;
      }
      const PairPlan& current = plans[count - 1];
      const std::size_t take = std::min(M - j, (kBlockSamples - used) & ~std::size_t(1));
      spans.push_back({count - 1, used, take, j});
      build(c, current, j, take, block, used);
      used += take;
      j += take;
      if (j == M) {
        ++i;
        planned = false;
      }
    }
    // The hull spans' warm simplices (the kernel reads them for convex-convex runs only), now that `plans` no
    // longer grows in this block.
    for (const Span& sp : spans) {
      const PairPlan& p = plans[sp.plan];
      if (p.type_a == ShapeType::convex && p.type_b == ShapeType::convex)
        std::fill_n(block.warm.data() + sp.first, sp.count, p.warm.count > 0 ? &p.warm : nullptr);
    }
    // Runs of one type pair through the kernel (or the scalar path).
    for (std::size_t s = 0; s < spans.size();) {
      const PairPlan& p = plans[spans[s].plan];
      std::size_t e = s + 1;
      while (e < spans.size() && plans[spans[e].plan].type_a == p.type_a && plans[spans[e].plan].type_b == p.type_b)
        ++e;
      const std::size_t first = spans[s].first, count = spans[e - 1].first + spans[e - 1].count - first;
      solve_samples<T>(c, block, first, count, p.wide, p.type_a, p.type_b);
      s = e;
    }
    // Reduce: a span that ends its pair finishes it; the last span may continue in the next block.
    for (const Span& sp : spans) {
      const PairPlan& p = plans[sp.plan];
      if (sp.j0 == 0) {
        sums = Sums();
        for (int e = 0; e < 10; ++e) sums.g0[e] = p.g0[e];
      }
      accumulate(c, block, sp.first, sp.count, sums);
      if (sp.j0 + sp.count == M) finish_pair(c, p, sums, out, lanes);
    }
  }
}

}  // namespace

void smoothed0(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
               const DerivativeOptions& o, const PairResults& results, DerivativeResults& d) {
  const std::size_t n = batch.size();
  size_for(d, n, true);  // every pair writes all its entries
  // The first-order start needs the normal's Jacobian: the analytic derivatives, when some pair has curvature.
  bool any_curved = false;
  for (std::size_t i = 0; i < n && !any_curved; ++i)
    any_curved = curved(shapes, batch.shape_a[i]) || curved(shapes, batch.shape_b[i]);
  // Reused by the calls of this thread up to 2^14 pairs (15 MB): a fresh 120 doubles per pair were zero-filled and
  // page-faulted at every call, a fixed cost that small M feels.
  thread_local DerivativeResults reused;
  DerivativeResults fresh;
  DerivativeResults& predictor = n <= (std::size_t(1) << 14) ? reused : fresh;
  if (any_curved) {
    DerivativeOptions analytic = o;
    analytic.method = DerivativeMethod::analytic;
    analytic_normal_b(shapes, batch, results, analytic, query.threads, resolve_instruction_set(query.isa), predictor);
  }
  QueryOptions q = query;
  q.solver = resolve_solver(query.solver, query.level);
  const Context c{shapes, batch, results, o, q, resolve_instruction_set(query.isa),
                  any_curved ? &predictor : nullptr, pair_view(shapes, batch)};
  for_pairs(query.threads, n, [&](std::size_t begin, std::size_t end) {
    if (query.precision == Precision::float32) run_pairs<float>(c, begin, end, d);
    else run_pairs<double>(c, begin, end, d);
  });
}

}  // namespace batchcol::detail
