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
#include <vector>

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

/// What the samples of pair i share, in A's frame: B's pose (R, t), the unperturbed answer g0 (distance, witness
/// points, normal), the noise scales, the first GJK direction without perturbation and its first-order change P z.
struct PairPlan {
  std::size_t i = 0;
  bool ok = false;  // false: no nominal witness, or b has no finite size (store_nothing)
  Eigen::Matrix3d Ra, R;
  Eigen::Vector3d ta, t, warm;
  Eigen::Matrix<double, 10, 1> g0;
  Noise s;
  bool predict = false;
  Eigen::Matrix<double, 3, 6> P;
  ShapeType type_a = ShapeType::sphere, type_b = ShapeType::sphere;
  bool wide = false;  // the type pair runs through gjk_samples
  kernels::simd::SamplePlan samples;  // the above as build_samples() reads it
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
  p.Ra = R_a;
  p.ta = c.batch.translation_a[i];
  p.R = R_a.transpose() * R_b;
  const Eigen::Vector3d t_b = c.batch.translation_b[i];
  p.t = R_a.transpose() * (t_b - p.ta);
  p.g0 << g.distance, R_a.transpose() * (g.witness_a - p.ta), R_a.transpose() * (g.witness_b - p.ta),
      R_a.transpose() * g.normal;
  const Eigen::Vector3d d = c.results.direction.size() == c.batch.size() ? Eigen::Vector3d(c.results.direction[i])
                                                                         : Eigen::Vector3d(-g.normal);
  p.warm = R_a.transpose() * d;
  const auto& types = ShapeTableAccess::types(c.shapes);
  p.type_a = types[c.batch.shape_a[i]];
  p.type_b = types[c.batch.shape_b[i]];
  p.wide = wide_type_pair(p.type_a, p.type_b, c.query);
  p.predict = false;
  if (c.predictor && (c.predictor->status[i] == DerivativeStatus::smooth ||
                      c.predictor->status[i] == DerivativeStatus::zero_curvature)) {
    // A sample moves b about its own origin by v_n = s_t Ra z_v and w = s_w Ra z_w (z in A's frame): the world
    // twist (v_n + t_b x w, w); the normal moves by J_n of that, taken back to A's frame.
    const Mat36 J = c.predictor->normal_wrt_b[i];
    const Eigen::Matrix3d Jv = J.leftCols<3>(), Jw = J.rightCols<3>();
    p.P.leftCols<3>() = p.s.translation * (R_a.transpose() * Jv * R_a);
    p.P.rightCols<3>() = p.s.rotation * (R_a.transpose() * (Jv * skew(t_b) + Jw) * R_a);
    p.predict = p.P.allFinite();
  }
  kernels::simd::SamplePlan& sp = p.samples;
  sp.key = splitmix64(splitmix64(c.o.seed) ^ i);  // CounterRng's (seed, pair) half of the key
  for (int r = 0; r < 3; ++r) {
    for (int q = 0; q < 3; ++q) sp.R0[3 * r + q] = p.R(r, q);
    sp.t0[r] = p.t[r];
    sp.n0[r] = p.g0[7 + r];
    sp.first[r] = p.warm[r];
    for (int e = 0; e < 6; ++e) sp.P[6 * r + e] = p.predict ? p.P(r, e) : 0.0;
  }
  sp.translation = p.s.translation;
  sp.rotation = p.s.rotation;
  sp.predict = p.predict;
}

/// One block's samples, structure of arrays (the kernel's layout), and their answers, one row of kRow per sample
/// (distance, witness a, witness b, normal, two zeros: the reduction reads a sample's values as whole registers).
struct Block {
  enum Array { kR = 0, kT = 9, kDir = 12, kZ = 15, kArrays = 21 };
  static constexpr std::size_t kRow = 12;
  std::size_t capacity = 0, count = 0;
  std::vector<double> data, values;
  std::vector<std::uint32_t> shape_a, shape_b, fallback;
  std::vector<Status> status;
  double* at(int array) { return data.data() + static_cast<std::size_t>(array) * capacity; }
  double* row(std::size_t k) { return values.data() + kRow * k; }
  void reserve(std::size_t n) {
    capacity = n;
    data.resize(kArrays * n);
    values.assign(kRow * n, 0.0);  // the padding stays 0
    shape_a.resize(n);
    shape_b.resize(n);
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
/// pairs (2k: z drawn from the key (seed, pair, k) in A's frame) at slot .. slot + evens, their copies (2k+1: -z,
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

/// The estimator from the sums, mapped from A's frame and A-frame noise to the world, written straight into the
/// pair's StoreBlock slot. Loops in the operation order of the Eigen expressions they replace (products
/// summed k = 0, 1, 2 left to right, except row 2 of Ra times a 3-row block, which Eigen computes after its 2-row
/// packet as a0 + (a1 + a2); the same divisions; the rigid-motion blocks' signed zeros), so the bits are those of
/// the Eigen version; that one cost ~1600 instructions per pair (block temporaries, a PairJacobians copy
/// and write_jacobians()), more than four M = 4 samples' GJK.
void finish_pair(const Context& c, const PairPlan& p, const Sums& sums, StoreBlock& out) {
  const std::size_t i = p.i;
  if (sums.valid == 0) return store_nothing(out, i);
  DerivativeResults& d = out.d;
  const double valid = double(sums.valid);
  double mean[10];
  for (int r = 0; r < 10; ++r) mean[r] = sums.mean[r] / valid;
  // Column-major like the sums, GT[e][r] = G(r, e), two rows per SSE2 register where the operation runs along a
  // column (every entry still gets its own operations in the scalar order: the bits do not change).
  using V2 = double __attribute__((vector_size(16)));
  const auto ld = [](const double* p) { V2 v; std::memcpy(&v, p, sizeof v); return v; };
  const auto st = [](double* p, V2 v) { std::memcpy(p, &v, sizeof v); };
  // G = sums / valid, divided by the noise scale: the score of the Gaussian is S^-1 z.
  double GT[6][10];
  for (int e = 0; e < 6; ++e) {
    const double s = e < 3 ? p.s.translation : p.s.rotation;
    for (int r = 0; r < 10; r += 2) st(&GT[e][r], ld(&sums.G[e][r]) / valid / s);
  }
  // Values and noise to the world: v_world - g0_world = Ra (v_A - g0_A) for the points and the normal, and the
  // world noise is Ra z.
  double Ra[3][3];
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) Ra[r][q] = p.Ra(r, q);
  for (int e = 0; e < 6; ++e)
    for (int r = 1; r < 10; r += 3) {
      double* g = &GT[e][r];
      const double g0 = g[0], g1 = g[1], g2 = g[2];
      for (int q = 0; q < 2; ++q) g[q] = (Ra[q][0] * g0 + Ra[q][1] * g1) + Ra[q][2] * g2;
      g[2] = Ra[2][0] * g0 + (Ra[2][1] * g1 + Ra[2][2] * g2);
    }
  // The noise moved b about its own origin t_b: a world twist (v, w) is the noise coordinates (v - [t_b]x w, w).
  const Eigen::Vector3d t_b = c.batch.translation_b[i];
  const double S[3][3] = {{0.0, -t_b.z(), t_b.y()}, {t_b.z(), 0.0, -t_b.x()}, {-t_b.y(), t_b.x(), 0.0}};  // skew()
  for (int r = 0; r < 10; r += 2) {  // G.leftCols() * Ra^T, G.rightCols() * Ra^T, then minus G.leftCols() [t_b]x
    V2 col[6], w[6];
    for (int e = 0; e < 6; ++e) col[e] = ld(&GT[e][r]);
    for (int h = 0; h < 6; h += 3)
      for (int q = 0; q < 3; ++q) w[h + q] = (col[h] * Ra[q][0] + col[h + 1] * Ra[q][1]) + col[h + 2] * Ra[q][2];
    for (int q = 0; q < 3; ++q) w[3 + q] -= (w[0] * S[0][q] + w[1] * S[1][q]) + w[2] * S[2][q];
    for (int e = 0; e < 6; ++e) st(&GT[e][r], w[e]);
  }
  const auto world = [&](int r0, double* v) {  // Ra m + ta (r0 = 1, 4) or Ra m (r0 = 7)
    for (int q = 0; q < 2; ++q) v[q] = (Ra[q][0] * mean[r0] + Ra[q][1] * mean[r0 + 1]) + Ra[q][2] * mean[r0 + 2];
    v[2] = Ra[2][0] * mean[r0] + (Ra[2][1] * mean[r0 + 1] + Ra[2][2] * mean[r0 + 2]);
  };
  double xa[3], xb[3], n[3];
  world(1, xa), world(4, xb), world(7, n);
  for (int q = 0; q < 3; ++q) xa[q] += p.ta[q], xb[q] += p.ta[q];
  double* slot = out.slot(i);
  constexpr std::size_t kS = StoreBlock::kStride;
  for (int e = 0; e < 6; ++e)
    slot[(store_at::distance_a + e) * kS] = -GT[e][0], slot[(store_at::distance_b + e) * kS] = GT[e][0];
  // The a-twist blocks: [I, -[x]x] - the b-twist block (rigid_motion(); [0, -[n]x] for the normal), -[x]x with
  // rigid_motion()'s -0.0 diagonal.
  const auto a_block = [&](std::size_t e0, const double* x, double identity, int r0) {
    const double minus_skew[3][3] = {{-0.0, x[2], -x[1]}, {-x[2], -0.0, x[0]}, {x[1], -x[0], -0.0}};
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 6; ++q) {
        const double m = q < 3 ? (r == q ? identity : 0.0) : minus_skew[r][q - 3];
        slot[(e0 + 6 * r + q) * kS] = m - GT[q][r0 + r];
      }
  };
  const auto b_block = [&](std::size_t e0, int r0) {
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 6; ++q) slot[(e0 + 6 * r + q) * kS] = GT[q][r0 + r];
  };
  a_block(store_at::witness_a_a, xa, 1.0, 1), b_block(store_at::witness_a_b, 1);
  a_block(store_at::witness_b_a, xb, 1.0, 4), b_block(store_at::witness_b_b, 4);
  a_block(store_at::normal_a, n, 0.0, 7), b_block(store_at::normal_b, 7);
  d.smoothed_distance[i] = mean[0];
  d.smoothed_witness_a.set(i, Eigen::Vector3d(xa[0], xa[1], xa[2]));
  d.smoothed_witness_b.set(i, Eigen::Vector3d(xb[0], xb[1], xb[2]));
  d.smoothed_normal.set(i, Eigen::Vector3d(n[0], n[1], n[2]));
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
  StoreBlock out(d);
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
      if (sp.j0 + sp.count == M) finish_pair(c, p, sums, out);
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
    analytic_normal_b(shapes, batch, results, analytic, query.threads, predictor);
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
