// The sample entry of the SIMD GJK (kernels::simd::gjk_samples, the smoothed0 derivatives' perturbed copies):
// every sample it answers has the bits of the scalar path (kernels::solve_pair: setup, GJK, completion) on the same
// relative pose and first direction, for every instruction set and both precisions, runs of several pairs included;
// the samples it hands back are exactly those the scalar path must finish beyond GJK (overlap at the penetration
// level).
#include "kernel_views.hpp"  // engine/src: pair_view
#include "kernels/narrowphase.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

struct Samples {
  std::vector<std::uint32_t> shape_a, shape_b;
  std::vector<double> R[9], t[3], dir[3];
  std::size_t size() const { return shape_a.size(); }
};

/// `per_pair` samples of each of `pairs` pairs of types (a, b): B's pose in A's frame perturbed around a random
/// one; first directions finite (a warm start), zero or NaN (the centres' difference).
Samples make_samples(Rng& rng, ShapeTable& shapes, ShapeType a, ShapeType b, int pairs, int per_pair, double reach) {
  Samples s;
  for (int p = 0; p < pairs; ++p) {
    const auto ia = shapes.add(testing::random_shape(rng, a)), ib = shapes.add(testing::random_shape(rng, b));
    const Eigen::Matrix3d R0 = testing::random_rotation(rng).toRotationMatrix();
    const Eigen::Vector3d t0 = testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, reach);
    for (int j = 0; j < per_pair; ++j) {
      const Eigen::Matrix3d R =
          Eigen::AngleAxisd(0.05, testing::random_unit_vector(rng)).toRotationMatrix() * R0;
      const Eigen::Vector3d t = t0 + 0.01 * testing::random_vector(rng);
      Eigen::Vector3d d = testing::random_unit_vector(rng);
      if (j % 5 == 3) d.setZero();
      if (j % 7 == 4) d.x() = std::numeric_limits<double>::quiet_NaN();
      s.shape_a.push_back(ia);
      s.shape_b.push_back(ib);
      for (int e = 0; e < 9; ++e) s.R[e].push_back(R(e / 3, e % 3));
      for (int e = 0; e < 3; ++e) s.t[e].push_back(t[e]), s.dir[e].push_back(d[e]);
    }
  }
  return s;
}

template <class T>
void check(const ShapeTable& shapes, const Samples& s, ShapeType a, ShapeType b, const QueryOptions& options,
           InstructionSet isa, bool expect_fallbacks) {
  const std::size_t n = s.size();
  kernels::simd::SampleBatch in;
  in.shape_a = s.shape_a.data();
  in.shape_b = s.shape_b.data();
  in.samples = n;
  for (int e = 0; e < 9; ++e) in.R[e] = s.R[e].data();
  for (int e = 0; e < 3; ++e) in.t[e] = s.t[e].data(), in.direction[e] = s.dir[e].data();
  std::vector<Status> status(n, Status::invalid_input);
  std::vector<double> dist(n), wa[3], wb[3], nn[3];
  kernels::simd::SampleResults out;
  out.status = status.data();
  out.distance = dist.data();
  for (int e = 0; e < 3; ++e) {
    wa[e].resize(n), wb[e].resize(n), nn[e].resize(n);
    out.witness_a[e] = wa[e].data(), out.witness_b[e] = wb[e].data(), out.normal[e] = nn[e].data();
  }
  std::vector<std::uint32_t> fallback(n);
  PairBatch empty;
  const std::size_t left = kernels::simd::gjk_samples<T>(isa, detail::pair_view(shapes, empty), a, b, in, options,
                                                         out, fallback.data());
  std::vector<bool> handed_back(n, false);
  for (std::size_t f = 0; f < left; ++f) handed_back[fallback[f]] = true;
  if (expect_fallbacks) EXPECT_GT(left, 0u);
  else EXPECT_LE(left, n / 20);  // rare float stalls redone in double
  int compared = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (handed_back[k]) continue;
    kernels::RelativePose X;
    for (int e = 0; e < 9; ++e) X.R(e / 3, e % 3) = s.R[e][k];
    for (int e = 0; e < 3; ++e) X.t[e] = s.t[e][k];
    const Eigen::Vector3d warm(s.dir[0][k], s.dir[1][k], s.dir[2][k]);
    const kernels::PairOutput<T> r =
        kernels::solve_pair<T>(detail::ShapeTableAccess::view(shapes, s.shape_a[k]),
                               detail::ShapeTableAccess::view(shapes, s.shape_b[k]), X, warm, options);
    ASSERT_EQ(status[k], r.status) << "sample " << k;
    ASSERT_TRUE(same(dist[k], double(r.distance))) << "sample " << k << ": " << dist[k] << " vs " << r.distance;
    for (int e = 0; e < 3; ++e) {
      ASSERT_TRUE(same(wa[e][k], double(r.witness_a[e]))) << "sample " << k;
      ASSERT_TRUE(same(wb[e][k], double(r.witness_b[e]))) << "sample " << k;
      ASSERT_TRUE(same(nn[e][k], double(r.normal[e]))) << "sample " << k;
    }
    ++compared;
  }
  EXPECT_GT(compared, 0);
}

TEST(WideGjkSamples, SameBitsAsTheScalarPathOnEveryInstructionSet) {
  QueryOptions options;
  options.level = QueryLevel::witness;
  options.solver = resolve_solver(options.solver, options.level);
  const std::pair<ShapeType, ShapeType> types[] = {{ShapeType::ellipsoid, ShapeType::ellipsoid},
                                                   {ShapeType::convex, ShapeType::convex},
                                                   {ShapeType::box, ShapeType::cylinder},
                                                   {ShapeType::cone, ShapeType::ellipsoid},
                                                   {ShapeType::capsule, ShapeType::convex}};
  for (const auto& [a, b] : types) {
    ASSERT_FALSE(kernels::may_have_closed_form(a, b, options));
    Rng rng(17);
    ShapeTable shapes;
    // 13 samples per pair: lanes refill across pairs, and a pair's samples are split between lanes.
    const Samples s = make_samples(rng, shapes, a, b, 9, 13, 1.5);
    for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
      if (!kernels::simd::cpu_has(isa)) continue;
      SCOPED_TRACE(std::string(to_string(a)) + "-" + to_string(b) + " " + to_string(isa));
      check<double>(shapes, s, a, b, options, isa, false);
      QueryOptions single = options;
      single.precision = Precision::float32;
      check<float>(shapes, s, a, b, single, isa, false);
    }
  }
}

/// One run of gjk_samples on `s` with the per-sample warm simplices `warm` (null entries: none): the answers.
template <class T> struct WarmRun {
  std::vector<Status> status;
  std::vector<double> values;  // distance, witness a, witness b, normal: 10 per sample
  std::size_t left = 0;
};
template <class T>
WarmRun<T> run_warm(const ShapeTable& shapes, const Samples& s, const std::vector<const kernels::simd::WarmSimplex*>& warm,
                    const QueryOptions& options, InstructionSet isa) {
  const std::size_t n = s.size();
  kernels::simd::SampleBatch in;
  in.shape_a = s.shape_a.data();
  in.shape_b = s.shape_b.data();
  in.samples = n;
  in.warm = warm.data();
  for (int e = 0; e < 9; ++e) in.R[e] = s.R[e].data();
  for (int e = 0; e < 3; ++e) in.t[e] = s.t[e].data(), in.direction[e] = s.dir[e].data();
  WarmRun<T> r;
  r.status.assign(n, Status::invalid_input);
  r.values.assign(10 * n, std::numeric_limits<double>::quiet_NaN());
  kernels::simd::SampleResults out;
  out.status = r.status.data();
  out.stride = 10;
  out.distance = r.values.data();
  for (int e = 0; e < 3; ++e) {
    out.witness_a[e] = r.values.data() + 1 + e;
    out.witness_b[e] = r.values.data() + 4 + e;
    out.normal[e] = r.values.data() + 7 + e;
  }
  std::vector<std::uint32_t> fallback(n);
  PairBatch empty;
  r.left = kernels::simd::gjk_samples<T>(isa, detail::pair_view(shapes, empty), ShapeType::convex, ShapeType::convex,
                                         in, options, out, fallback.data());
  return r;
}

// Witness-level options of precision T at `tolerance`, as the warm-sample tests run them.
template <class T> QueryOptions warm_options(double tolerance) {
  QueryOptions options;
  options.level = QueryLevel::witness;
  options.solver = resolve_solver(options.solver, options.level);
  if (std::is_same_v<T, float>) options.precision = Precision::float32;
  options.tolerance = tolerance;
  return options;
}

// Every sample of run r has the status and the ten values of run base, bit for bit.
template <class T> void expect_same_run(const WarmRun<T>& r, const WarmRun<T>& base) {
  ASSERT_EQ(r.left, base.left);
  for (std::size_t k = 0; k < base.status.size(); ++k) {
    ASSERT_EQ(r.status[k], base.status[k]) << "sample " << k;
    for (int e = 0; e < 10; ++e) ASSERT_TRUE(same(r.values[10 * k + e], base.values[10 * k + e])) << "sample " << k;
  }
}

// A warm simplex (the smoothed0 samples of hull pairs start from their pair's nominal simplex) changes where GJK
// starts, not what it certifies: whatever vertex pairs it names (here random ones, degenerate and repeated
// included), every sample converges, to the distance of the cold start within the certified tolerance (both are
// within max(tolerance, floor) of the exact distance), with the same bits on every instruction set.
template <class T> void check_warm(double tolerance) {
  const QueryOptions options = warm_options<T>(tolerance);
  Rng rng(29);
  ShapeTable shapes;
  const Samples s = make_samples(rng, shapes, ShapeType::convex, ShapeType::convex, 12, 11, 2.0);
  std::vector<kernels::simd::WarmSimplex> simplices(s.size());
  std::vector<const kernels::simd::WarmSimplex*> warm(s.size(), nullptr);
  const auto& hulls = detail::ShapeTableAccess::hulls(shapes);
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (k % 6 == 5) continue;  // some samples without one
    kernels::simd::WarmSimplex& w = simplices[k];
    w.count = 1 + std::uint32_t(testing::uniform(rng, 0.0, 3.0)) % 3;
    for (std::uint32_t m = 0; m < w.count; ++m) {
      w.a[m] = std::uint32_t(testing::uniform(rng, 0.0, double(hulls[s.shape_a[k]].vertex_count))) %
               hulls[s.shape_a[k]].vertex_count;
      w.b[m] = k % 4 == 1 ? w.b[0]  // repeated B vertices: a degenerate simplex
                          : std::uint32_t(testing::uniform(rng, 0.0, double(hulls[s.shape_b[k]].vertex_count))) %
                                hulls[s.shape_b[k]].vertex_count;
    }
    warm[k] = &w;
  }
  const std::vector<const kernels::simd::WarmSimplex*> cold(s.size(), nullptr);
  const InstructionSet first = InstructionSet::scalar;
  const WarmRun<T> base = run_warm<T>(shapes, s, warm, options, first);
  const WarmRun<T> reference = run_warm<T>(shapes, s, cold, options, first);
  EXPECT_LE(base.left + reference.left, s.size() / 20);  // rare float stalls redone in double (left unwritten)
  const double floor = 16.0 * std::numeric_limits<T>::epsilon() * 4.0;  // tolerance_floor of these ~3 m problems
  int compared = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (base.status[k] == Status::invalid_input || reference.status[k] == Status::invalid_input) continue;
    ASSERT_EQ(base.status[k], reference.status[k]) << "sample " << k;
    if (base.status[k] != Status::converged) continue;
    // Overlapping samples (centres up to 2 m apart) end at the witness level with a NaN distance: in both runs.
    ASSERT_EQ(std::isnan(base.values[10 * k]), std::isnan(reference.values[10 * k])) << "sample " << k;
    if (std::isnan(reference.values[10 * k])) continue;
    EXPECT_NEAR(base.values[10 * k], reference.values[10 * k], 2.0 * std::max(tolerance, floor)) << "sample " << k;
    ++compared;
  }
  EXPECT_GT(compared, int(s.size()) / 2);
  for (InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
    if (!kernels::simd::cpu_has(isa)) continue;
    SCOPED_TRACE(to_string(isa));
    expect_same_run(run_warm<T>(shapes, s, warm, options, isa), base);
  }
}

TEST(WideGjkSamples, AnyWarmSimplexGivesTheCertifiedAnswerWithTheSameBitsOnEveryInstructionSet) {
  check_warm<double>(1e-8);
  check_warm<float>(1e-5);
}

// The smoothed0 layout: each pair's samples consecutive, sharing one warm simplex (the pair's). Registers whose W
// samples are one pair's are loaded W at a time (wide_gjk_samples.inl's load_all(), its warm_start_lanes()), the
// others lane by lane; per-sample copies of the same simplices (other pointers, the same vertex pairs) make every
// register load lane by lane. Both must give the same bits, on every instruction set, as the scalar set (W = 1: in
// double every one-sample register is one pair's, so it loads through load_all() too; the lane-by-lane path is the
// AVX2 / AVX-512 runs on per-sample copies, and float, which always loads lane by lane). 13 samples a pair:
// registers straddle pairs; 1-3 vertices, degenerate ones included; zero and NaN first directions (the centres'
// difference).
template <class T> void check_shared_warm(double tolerance) {
  const QueryOptions options = warm_options<T>(tolerance);
  Rng rng(31);
  ShapeTable shapes;
  const int pairs = 24, per_pair = 13;
  const Samples s = make_samples(rng, shapes, ShapeType::convex, ShapeType::convex, pairs, per_pair, 2.0);
  const auto& hulls = detail::ShapeTableAccess::hulls(shapes);
  std::vector<kernels::simd::WarmSimplex> simplices(pairs), copies(s.size());
  std::vector<const kernels::simd::WarmSimplex*> shared(s.size(), nullptr), own(s.size(), nullptr);
  for (int p = 0; p < pairs; ++p) {
    kernels::simd::WarmSimplex& w = simplices[std::size_t(p)];
    const std::size_t k0 = std::size_t(p) * per_pair;
    w.count = std::uint32_t(p % 4);  // 0: no warm start
    for (std::uint32_t m = 0; m < w.count; ++m) {
      const std::uint32_t na = hulls[s.shape_a[k0]].vertex_count, nb = hulls[s.shape_b[k0]].vertex_count;
      w.a[m] = std::uint32_t(testing::uniform(rng, 0.0, double(na))) % na;
      w.b[m] = p % 8 == 7 ? w.b[0] : std::uint32_t(testing::uniform(rng, 0.0, double(nb))) % nb;
    }
    for (int j = 0; j < per_pair; ++j) {
      shared[k0 + std::size_t(j)] = &w;
      copies[k0 + std::size_t(j)] = w;
      own[k0 + std::size_t(j)] = &copies[k0 + std::size_t(j)];
    }
  }
  const WarmRun<T> base = run_warm<T>(shapes, s, shared, options, InstructionSet::scalar);
  int converged = 0;
  for (Status st : base.status) converged += st == Status::converged;
  EXPECT_GT(converged, int(s.size()) / 2);
  for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
    if (!kernels::simd::cpu_has(isa)) continue;
    for (const auto* warm : {&shared, &own}) {
      SCOPED_TRACE(std::string(to_string(isa)) + (warm == &shared ? " shared" : " per-sample copies"));
      expect_same_run(run_warm<T>(shapes, s, *warm, options, isa), base);
    }
  }
}

TEST(WideGjkSamples, OnePairsRegistersLoadedAtOnceGiveTheLaneByLaneBits) {
  check_shared_warm<double>(1e-8);
  check_shared_warm<double>(1e-12);
  check_shared_warm<float>(1e-5);
}

TEST(WideGjkSamples, OverlapsAtThePenetrationLevelAreHandedBack) {
  QueryOptions options;
  options.level = QueryLevel::penetration;
  options.solver = resolve_solver(options.solver, options.level);
  Rng rng(23);
  ShapeTable shapes;
  // Centres within 0.3 of each other: many samples overlap, some do not.
  const Samples s = make_samples(rng, shapes, ShapeType::ellipsoid, ShapeType::convex, 12, 8, 0.3);
  check<double>(shapes, s, ShapeType::ellipsoid, ShapeType::convex, options, kernels::simd::detected_instruction_set(),
                true);
}

}  // namespace
}  // namespace batchcol
