// GJK groups answered straight from the batch arrays (kernels::simd::gjk_pairs) give, pair by pair, the bits of the
// scalar reference: the relative pose as the executor computes it, kernels::solve_pair (scalar GJK), the output
// mapped to the world frame. Invalid pairs get invalid_input and NaN / 0 everywhere else.
#include "kernel_views.hpp"  // engine/src: pair_view, result_view
#include "kernels/math.hpp"
#include "kernels/minkowski.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

namespace batchcol {
namespace {

using testing::Rng;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

struct Scene {
  ShapeTable shapes;
  PairBatch batch;
};

/// Every plain convex type (two of each, one inflated), pairs near each other (separated, touching-close and
/// overlapping), and a few invalid pairs of every kind.
/// `concentric`: every concentric-th pair has B's centre at A's (zero first direction: the x axis instead).
Scene gjk_scene(std::size_t pairs, std::uint64_t seed, std::size_t concentric = 0) {
  Rng rng(seed);
  Scene s;
  for (ShapeType t : {ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::cylinder, ShapeType::cone,
                      ShapeType::ellipsoid, ShapeType::convex}) {
    s.shapes.add(testing::random_shape(rng, t));
    s.shapes.add(testing::random_shape(rng, t).inflated(0.01));
  }
  for (std::size_t i = 0; i < pairs; ++i) {
    const auto a = static_cast<std::uint32_t>(rng() % s.shapes.size());
    const auto b = static_cast<std::uint32_t>(rng() % s.shapes.size());
    Pose pa{testing::random_vector(rng) * 3.0, testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.6),
            testing::random_rotation(rng)};
    if (concentric != 0 && i % concentric == 3) pb.translation = pa.translation;
    std::uint32_t ia = a;
    switch (i % 97) {  // invalid pairs, scattered
      case 5: pa.rotation.coeffs()[1] = kNan; break;
      case 17: pb.rotation.coeffs() *= 1.01; break;  // not unit
      case 29: pb.translation.y() = std::numeric_limits<double>::infinity(); break;
      case 41: ia = static_cast<std::uint32_t>(s.shapes.size() + 3); break;
      default: break;
    }
    s.batch.add(ia, pa, b, pb);
  }
  return s;
}

/// The executor's relative pose (engine/src/executor.cpp prepare_pair), spelled out the same way.
bool unit(double q[4]) {
  const double norm = std::sqrt(((q[0] * q[0] + q[1] * q[1]) + q[2] * q[2]) + q[3] * q[3]);
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) return false;
  for (int c = 0; c < 4; ++c) q[c] /= norm;
  return true;
}

/// Pairs the executor answers by a SIMD closed form (its own rule, kernels::simd::wide_closed_form), which a scalar
/// solve_pair() does not reproduce bit for bit (they work in the world frame; the box SAT kernel leaves the
/// direction NaN): sphere/capsule pairs, sphere against cylinder or cone (tests/engine/point_solids_test.cpp),
/// box-box at boolean level.
bool simd_closed_form(ShapeType a, ShapeType b, const QueryOptions& o) {
  return kernels::simd::wide_closed_form(a, b, o) != kernels::simd::WideClosedForm::none;
}

/// Entry i of a result array, NaN when the level left the array empty.
double at(const std::vector<double>& v, std::size_t i) { return v.empty() ? kNan : v[i]; }
Eigen::Vector3d at(const Vec3Array& v, std::size_t i) { return {at(v.x, i), at(v.y, i), at(v.z, i)}; }

/// A boolean double pair of the batch-array GJK (kernels::simd::gjk_pairs: the gate, the float pass and its double
/// certificate, wide_gjk_pairs.inl run_certified()), given r[i] = the double GJK's answer:
///  - the gate: w0 = D.support(-d0) in double along the setup's first direction d0; if <w0, d0> / |d0| > the core
///    margin, the gate's answer (converged, collide 0, d0 mapped to the world, 1 iteration);
///  - else the float GJK answers (solve_pair<float>, whose bits the float pass has), then
///  - float separated (collide 0): the certificate, D.support(-v) in double for the float direction v widened, is
///    computed here; accepted iff <w, v> / |v| > the double setup's core margin: the float answer (converged,
///    collide 0, v mapped to the world, the float iterations);
///  - float colliding: the certificate needs the float simplex's directions, which solve_pair() does not give, so
///    either answer is accepted: the float one (converged, collide 1, the float direction and iterations) or the
///    double GJK's with the iterations of both passes (told apart by the iterations);
///  - else the double GJK's answer with the iterations of both passes.
/// Whichever it is, collide must be the double GJK's (checked by expect_same_results on every pair).
void certified_reference(const OwnedShapeView& va, const OwnedShapeView& vb, const kernels::RelativePose& X,
                         const QueryOptions& o, const Eigen::Matrix3d& Ra, const PairResults& got, std::size_t i,
                         PairResults& r) {
  const kernels::PairSetup<double> setup =
      kernels::setup_pair<double>(va.view, vb.view, X, Eigen::Vector3d::Constant(kNan), o);
  const kernels::MinkowskiDifference<double> D{&setup.A, &setup.B, setup.X, {}, {}};
  const auto lower_bound = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d w = D.support(-v).w;
    return ((w.x() * v.x() + w.y() * v.y()) + w.z() * v.z()) / std::sqrt((v.x() * v.x() + v.y() * v.y()) + v.z() * v.z());
  };
  Eigen::Vector3d d0 = setup.initial_direction;
  if (!((d0.x() * d0.x() + d0.y() * d0.y()) + d0.z() * d0.z() > 0.0)) d0 = Eigen::Vector3d::UnitX();
  if (o.max_iterations >= 1 && lower_bound(d0) > setup.params.core_margin) {
    r.status[i] = Status::converged;
    r.collide[i] = 0;
    r.iterations[i] = 1;
    r.direction.set(i, kernels::mul<double>(Ra, d0));
    return;
  }
  const kernels::PairOutput<float> f =
      kernels::solve_pair<float>(va.view, vb.view, X, Eigen::Vector3d::Constant(kNan), o);
  const Eigen::Vector3d v = f.direction.cast<double>();
  bool take_float = false;
  if (f.status == Status::converged && !f.collide) {
    take_float = lower_bound(v) > setup.params.core_margin;
  } else if (f.status == Status::converged && f.collide) {
    take_float = got.iterations[i] == f.iterations;
  }
  if (take_float) {
    r.status[i] = Status::converged;
    r.collide[i] = f.collide ? 1 : 0;
    r.iterations[i] = f.iterations;
    r.direction.set(i, kernels::mul<double>(Ra, v));
  } else {
    r.iterations[i] += f.iterations;  // the double GJK's status, collide and direction (set by the caller)
  }
}

/// The scalar reference of every pair (every array full: NaN where the level computes nothing); pairs answered by a SIMD closed form take `got`'s values (they are not what
/// this test is about, and every other pair, sphere-box closed forms included, must match).
/// `certified` false: boolean double pairs get the plain double GJK's answer (status, collide, iterations,
/// direction) instead of certified_reference()'s.
template <class T>
PairResults reference(const Scene& s, const QueryOptions& o, const PairResults& got, bool certified = true) {
  PairResults r;
  const std::size_t n = s.batch.size();
  r.status.assign(n, Status::invalid_input);
  r.collide.assign(n, 0);
  r.iterations.assign(n, 0);
  r.distance.assign(n, kNan);
  for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal, &r.direction})
    v->x.assign(n, kNan), v->y.assign(n, kNan), v->z.assign(n, kNan);
  for (std::size_t i = 0; i < n; ++i) {
    const PairBatch& b = s.batch;
    double qa[4] = {b.rotation_a.w[i], b.rotation_a.x[i], b.rotation_a.y[i], b.rotation_a.z[i]};
    double qb[4] = {b.rotation_b.w[i], b.rotation_b.x[i], b.rotation_b.y[i], b.rotation_b.z[i]};
    const Eigen::Vector3d ta = b.translation_a[i], tb = b.translation_b[i];
    if (b.shape_a[i] >= s.shapes.size() || b.shape_b[i] >= s.shapes.size() || !unit(qa) || !unit(qb) ||
        !ta.allFinite() || !tb.allFinite())
      continue;
    if (simd_closed_form(s.shapes[b.shape_a[i]].type, s.shapes[b.shape_b[i]].type, o)) {
      r.status[i] = got.status[i], r.collide[i] = got.collide[i], r.iterations[i] = got.iterations[i];
      r.distance[i] = at(got.distance, i);
      for (auto m : {&PairResults::witness_a, &PairResults::witness_b, &PairResults::normal, &PairResults::direction})
        (r.*m).set(i, at(got.*m, i));
      continue;
    }
    const Eigen::Matrix3d Ra = kernels::rotation_matrix(qa[0], qa[1], qa[2], qa[3]);
    kernels::RelativePose X;
    X.R = kernels::transposed_product(Ra, kernels::rotation_matrix(qb[0], qb[1], qb[2], qb[3]));
    X.t = kernels::mul_transposed<double>(Ra, tb - ta);
    const OwnedShapeView va(s.shapes[b.shape_a[i]]), vb(s.shapes[b.shape_b[i]]);
    const kernels::PairOutput<T> p =
        kernels::solve_pair<T>(va.view, vb.view, X, Eigen::Vector3d::Constant(kNan), o);
    r.status[i] = p.status;
    r.collide[i] = p.collide ? 1 : 0;
    r.iterations[i] = p.iterations;
    if constexpr (std::is_same_v<T, double>) {
      const ShapeType type_a = s.shapes[b.shape_a[i]].type, type_b = s.shapes[b.shape_b[i]].type;
      // The types run_certified() takes (WideGjkPairs::certified_pays(), wide_gjk_pairs.inl).
      const auto pays = [](ShapeType t) {
        return t == ShapeType::box || t == ShapeType::cylinder || t == ShapeType::cone || t == ShapeType::ellipsoid ||
               t == ShapeType::sphere || t == ShapeType::capsule;
      };
      if (certified && o.level == QueryLevel::boolean && !kernels::may_have_closed_form(type_a, type_b, o) &&
          pays(type_a) && pays(type_b)) {
        r.direction.set(i, kernels::mul<double>(Ra, p.direction));
        certified_reference(va, vb, X, o, Ra, got, i, r);
        continue;
      }
    }
    if (o.level >= QueryLevel::distance) r.distance[i] = double(p.distance);
    if (o.level >= QueryLevel::witness) {
      r.witness_a.set(i, kernels::mul<double>(Ra, p.witness_a.template cast<double>()) + ta);
      r.witness_b.set(i, kernels::mul<double>(Ra, p.witness_b.template cast<double>()) + ta);
      r.normal.set(i, kernels::mul<double>(Ra, p.normal.template cast<double>()));
    }
    r.direction.set(i, kernels::mul<double>(Ra, p.direction.template cast<double>()));
  }
  // As collide(): no arrays for the values the level does not compute.
  if (o.level < QueryLevel::distance) r.distance.clear();
  if (o.level < QueryLevel::witness)
    for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal}) v->resize(0);
  return r;
}

/// The options of the bitwise tests below: 2 threads, so that the work is split across tiles.
QueryOptions bits_options(QueryLevel level, Solver solver, Precision precision, bool closed_forms) {
  QueryOptions o;
  o.level = level;
  o.solver = solver;
  o.precision = precision;
  o.closed_forms = closed_forms;
  o.threads = 2;
  return o;
}

template <class T> void expect_reference_bits(Precision precision) {
  const Scene s = gjk_scene(6000, precision == Precision::float64 ? 11 : 12);
  for (bool closed_forms : {false, true})
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness})
      for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
        // closed_forms off: every pair goes through GJK. On: the closed-form type pairs (sphere-box included) must
        // still be routed to their closed forms, and the rest to GJK.
        const QueryOptions o = bits_options(level, solver, precision, closed_forms);
        PairResults got;
        collide(s.shapes, s.batch, o, got);
        testing::expect_same_results(reference<T>(s, o, got), got,
                                     std::string(to_string(level)) + " " + to_string(solver) +
                                         (closed_forms ? " closed forms on" : " closed forms off"));
      }
}

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInDouble) { expect_reference_bits<double>(Precision::float64); }

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInFloat) { expect_reference_bits<float>(Precision::float32); }

/// Boolean runs of primitives take their first support point from the set-up (first_points(), and the certified
/// float pass's float_first_points()), along the set-up's first direction, the x axis where the centres' offset is
/// zero (start_lane()'s rule): pairs whose centres coincide keep the reference's bits, both precisions, every solver.
TEST(ExecutorGjkPairs, ConcentricBooleanPairsHaveTheScalarReferenceBits) {
  for (Precision precision : {Precision::float64, Precision::float32}) {
    const Scene s = gjk_scene(3000, 13, 5);
    for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      const QueryOptions o = bits_options(QueryLevel::boolean, solver, precision, false);
      PairResults got;
      collide(s.shapes, s.batch, o, got);
      const std::string what = std::string(to_string(solver)) + (precision == Precision::float64 ? " double" : " float");
      if (precision == Precision::float64) testing::expect_same_results(reference<double>(s, o, got), got, what);
      else testing::expect_same_results(reference<float>(s, o, got), got, what);
    }
  }
}

/// One shape-pair type straight through kernels::simd::gjk_pairs: many chunks of 64 pairs with lanes refilled
/// across chunk boundaries, small hulls (SIMD vertex scan) mixed with large ones (per-lane hill climbing with
/// hints); the kernel must hand back exactly the invalid pairs and answer every other one with the reference's bits.
template <class T> void expect_kernel_answers_valid_pairs(InstructionSet isa, QueryLevel level) {
  Rng rng(21);
  Scene s;
  for (int k = 0; k < 4; ++k) s.shapes.add(testing::random_shape(rng, ShapeType::convex));
  for (int k = 0; k < 3; ++k) {
    std::vector<Eigen::Vector3d> points;  // all on an ellipsoid: every point is a hull vertex
    const Eigen::Vector3d radii(testing::uniform(rng, 0.05, 0.3), testing::uniform(rng, 0.05, 0.3),
                                testing::uniform(rng, 0.05, 0.3));
    for (int i = 0; i < 150; ++i) points.push_back(testing::random_unit_vector(rng).cwiseProduct(radii));
    s.shapes.add(Shape::convex(points));
  }
  ASSERT_GE(s.shapes[6].hull->vertices.size(), 32u) << "a hull large enough for hill climbing";
  const std::size_t n = 700;
  std::vector<std::uint32_t> invalid;
  for (std::size_t i = 0; i < n; ++i) {
    Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.05, 0.5),
            testing::random_rotation(rng)};
    if (i % 53 == 7) pa.rotation.coeffs() *= 0.9, invalid.push_back(static_cast<std::uint32_t>(i));
    s.batch.add(static_cast<std::uint32_t>(rng() % 7), pa, static_cast<std::uint32_t>(rng() % 7), pb);
  }
  QueryOptions o;
  o.level = level;
  o.precision = std::is_same_v<T, float> ? Precision::float32 : Precision::float64;
  o.solver = resolve_solver(o.solver, o.level);  // as collide() does before calling the kernels
  PairResults got;
  got.resize(n);
  std::vector<std::uint32_t> pairs(n), fallback(n);
  for (std::size_t i = 0; i < n; ++i) pairs[i] = static_cast<std::uint32_t>(i);
  const std::size_t left = kernels::simd::gjk_pairs<T>(isa, detail::pair_view(s.shapes, s.batch),
                                                      ShapeType::convex, ShapeType::convex, pairs.data(), n, o,
                                                      detail::result_view(got), fallback.data());
  fallback.resize(left);
  std::sort(fallback.begin(), fallback.end());
  // Double never stalls above its floor here; float may hand back a stalled pair (redone in double elsewhere).
  if (std::is_same_v<T, double>) { EXPECT_EQ(fallback, invalid); }
  EXPECT_TRUE(std::includes(fallback.begin(), fallback.end(), invalid.begin(), invalid.end()));
  EXPECT_LE(left, invalid.size() + n / 100);
  const PairResults want = reference<T>(s, o, got);
  std::size_t compared = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::binary_search(fallback.begin(), fallback.end(), static_cast<std::uint32_t>(i))) continue;
    ++compared;
    EXPECT_EQ(want.status[i], got.status[i]) << i;
    EXPECT_EQ(want.collide[i], got.collide[i]) << i;
    EXPECT_EQ(want.iterations[i], got.iterations[i]) << i;
    const double values[2][10] = {
        {at(want.distance, i), at(want.witness_a.x, i), at(want.witness_a.y, i), at(want.witness_a.z, i),
         at(want.normal.x, i), at(want.normal.y, i), at(want.normal.z, i), want.direction.x[i], want.direction.y[i],
         want.direction.z[i]},
        {at(got.distance, i), at(got.witness_a.x, i), at(got.witness_a.y, i), at(got.witness_a.z, i),
         at(got.normal.x, i), at(got.normal.y, i), at(got.normal.z, i), got.direction.x[i], got.direction.y[i],
         got.direction.z[i]}};
    EXPECT_EQ(std::memcmp(values[0], values[1], sizeof values[0]), 0) << i;
  }
  EXPECT_GE(compared, n - invalid.size() - n / 100);
}

TEST(ExecutorGjkPairs, KernelAnswersEveryValidPairOfManyChunksAndLargeHulls) {
  for (InstructionSet isa : {InstructionSet::scalar, resolve_instruction_set(InstructionSet::automatic)})
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::witness}) {
      SCOPED_TRACE(std::string(to_string(isa)) + " " + to_string(level));
      expect_kernel_answers_valid_pairs<double>(isa, level);
      expect_kernel_answers_valid_pairs<float>(isa, level);
    }
}

/// The same query in float: a certified boolean double pair whose iterations are the float query's kept its float
/// answer (run_certified() adds the double GJK's iterations to a refused one's).
PairResults in_float_precision(const Scene& s, QueryOptions o) {
  o.precision = Precision::float32;
  PairResults r;
  collide(s.shapes, s.batch, o, r);
  return r;
}

/// Boolean double queries are answered by the float GJK plus a double certificate (wide_gjk_pairs.inl
/// run_certified()). Pairs placed within float error of touching, gaps and overlaps of 1e-12 .. 1e-4 times the
/// shapes' scale (1e-3 .. 1e3 m, extreme aspect ratios included), every GJK type pair of box, cylinder, cone,
/// 8-vertex hull, capsule and ellipsoid: every answer must be the double GJK's (collide, and the certified
/// reference's other bits), while the float GJK alone must get many of them wrong (the test fails if the
/// certificate is removed, or accepts an answer the double test would not).
TEST(ExecutorGjkPairs, BooleanDoubleNearTouchingPairsHaveTheDoubleAnswer) {
  Rng rng(77);
  Scene s;
  std::vector<double> scale_of;
  for (double scale : {1e-3, 1.0, 1e3})
    for (int aspect = 0; aspect < 2; ++aspect) {
      const double thin = aspect == 0 ? 0.5 : 1e-3;  // second set: plates, discs and needles
      std::vector<Eigen::Vector3d> points;
      for (int k = 0; k < 8; ++k)
        points.push_back(testing::random_unit_vector(rng).cwiseProduct(Eigen::Vector3d(1.0, 0.7, thin)) * scale);
      for (const Shape& shape : {Shape::box(scale, 0.6 * scale, thin * scale), Shape::cylinder(scale, thin * scale),
                                 Shape::cone(thin * scale, scale), Shape::convex(points),
                                 Shape::capsule(thin * scale, scale), Shape::ellipsoid(scale, 0.5 * scale, thin * scale)}) {
        s.shapes.add(shape);
        scale_of.push_back(scale);
      }
    }
  // Each pair is first placed apart (B beside A along a random u), its double witness query gives the distance d
  // and the normal n, and B is moved by (d - g) along n: the distance becomes the signed gap g exactly for g >= 0
  // (the witness points stay closest, the separating plane moves with B) and the cores overlap for g < 0.
  const std::uint32_t per_set = 6;
  PairBatch apart;
  std::vector<double> gaps;
  for (std::uint32_t set = 0; set < s.shapes.size() / per_set; ++set)
    for (std::uint32_t a = 0; a < per_set; ++a)
      for (std::uint32_t b = 0; b < per_set; ++b)
        for (double gap : {1e-12, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4})
          for (double sign : {1.0, -1.0})
            for (int k = 0; k < 2; ++k) {
              const std::uint32_t ia = set * per_set + a, ib = set * per_set + b;
              const Eigen::Vector3d u = testing::random_unit_vector(rng), at = testing::random_vector(rng);
              apart.add(ia, Pose{at, testing::random_rotation(rng)}, ib,
                        Pose{at + 3.0 * scale_of[ia] * u, testing::random_rotation(rng)});
              gaps.push_back(sign * gap * scale_of[ia]);
            }
  QueryOptions w;
  w.level = QueryLevel::witness;
  w.tolerance = 1e-15;
  w.max_iterations = 1000;
  w.closed_forms = false;
  PairResults placed;
  collide(s.shapes, apart, w, placed);
  std::vector<double> gap_of;  // the signed gap of s.batch's pair i
  for (std::size_t i = 0; i < apart.size(); ++i) {
    const Eigen::Vector3d n = placed.normal[i];
    if (placed.status[i] != Status::converged || placed.collide[i] || !n.allFinite()) continue;
    const double move = placed.distance[i] - gaps[i];
    Pose pb = apart.pose_b(i);
    pb.translation -= move * n;  // n points from A to B (wb - wa = d n)
    s.batch.add(apart.shape_a[i], apart.pose_a(i), apart.shape_b[i], pb);
    gap_of.push_back(gaps[i]);
  }
  ASSERT_GT(s.batch.size(), apart.size() * 9 / 10);
  QueryOptions o;
  o.level = QueryLevel::boolean;
  o.precision = Precision::float64;
  o.solver = resolve_solver(o.solver, o.level);
  o.threads = 2;
  PairResults got;
  collide(s.shapes, s.batch, o, got);
  // The double GJK's own answers (scalar path, solve_pair<double>): every collide must be theirs. (The other
  // bits are the certified path's, compared with certified_reference() in EveryPairHasTheScalarReferenceBits*;
  // near touching, pairs the double GJK cannot finish in the batch-array kernel go to the scalar path, whose
  // iterations certified_reference() does not model.)
  const PairResults want = reference<double>(s, o, got, false);
  std::size_t disagree = 0;
  // Allowed: a pair within the query's tolerance (absolute, o.tolerance = 1e-8 m) or 1e-8 (relative) of touching,
  // where the double GJK stopped at its tolerance (status converged, collide 1 from its lower bound) and the
  // certificate proved the constructed sign: collide() promises collide 0 only with a certified separating plane,
  // and the certified path has one there (measured: a capsule-cone pair at gap +1e-9 m, scale 1, and a
  // capsule-cylinder pair at +1e-9 m, scale 1e-3, both separated by construction, which the double GJK calls
  // colliding; the certified path keeps its proof, wide_gjk_pairs.inl certify()).
  for (std::size_t i = 0; i < got.size(); ++i) {
    const double within = std::max(o.tolerance, 1e-8 * scale_of[s.batch.shape_a[i]]);
    const bool close_call = std::abs(gap_of[i]) <= within && got.collide[i] == (gap_of[i] < 0 ? 1 : 0);
    if (!close_call) { EXPECT_EQ(want.collide[i], got.collide[i]) << i; }
    EXPECT_EQ(want.status[i], got.status[i]) << i;
    if (want.collide[i] != got.collide[i])
      std::printf("[measured] pair %zu %s-%s: double GJK %s collide %d (%d iterations), certified %s collide %d, gap %g, scale %g\n", i,
                  to_string(s.shapes[s.batch.shape_a[i]].type), to_string(s.shapes[s.batch.shape_b[i]].type),
                  to_string(want.status[i]), want.collide[i], want.iterations[i], to_string(got.status[i]),
                  got.collide[i], gap_of[i], scale_of[s.batch.shape_a[i]]);
    disagree += want.collide[i] != got.collide[i];
  }
  // The same query in float: a pair whose boolean double answer took more iterations than the float GJK's is one
  // whose float answer the certificate refused (or had none): near touching there must be many, else the
  // certificate would not be doing its job (accepting every float answer fails the comparison above too).
  const PairResults in_float = in_float_precision(s, o);
  std::size_t refused = 0, gjk_pairs = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (simd_closed_form(s.shapes[s.batch.shape_a[i]].type, s.shapes[s.batch.shape_b[i]].type, o)) continue;
    ++gjk_pairs;
    refused += got.iterations[i] != in_float.iterations[i];
  }
  std::printf("[measured] near-touching boolean double pairs through GJK: %zu, float answers refused: %zu, collide "
              "different from the double GJK's: %zu\n", gjk_pairs, refused, disagree);
  EXPECT_GT(refused, gjk_pairs / 20);
}

/// Spheres and capsules in boolean double groups (run_certified()): their overlaps end with the origin within the
/// swept radius of a segment or triangle of D, which certify_within() proves in double (wide_gjk_pairs.inl). Cores
/// apart and swept shapes overlapping, against every GJK type, closed forms off: every collide is the double GJK's,
/// the bits are the same on the scalar build and this CPU's best at 1 and 2 threads, and most colliding pairs keep
/// their float answer (same iterations as the float query: accepted, no double GJK after it), which fails if the
/// 2-3 vertex certificate refuses them.
TEST(ExecutorGjkPairs, BooleanDoubleSweptOverlapsAreProvenWithinTheRadius) {
  Rng rng(91);
  Scene s;
  for (const Shape& shape : {Shape::capsule(0.05, 0.2), Shape::capsule(0.1, 0.05).inflated(0.01), Shape::sphere(0.08),
                             Shape::sphere(0.03).inflated(0.02), Shape::box(0.2, 0.1, 0.05), Shape::cylinder(0.1, 0.2),
                             Shape::cone(0.1, 0.2), Shape::ellipsoid(0.2, 0.1, 0.05)})
    s.shapes.add(shape);
  const std::uint32_t rounded = 4;  // shapes [0, 4) are spheres and capsules
  for (std::size_t i = 0; i < 3000; ++i) {
    const auto a = static_cast<std::uint32_t>(rng() % rounded);
    const auto b = static_cast<std::uint32_t>(rng() % s.shapes.size());
    Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.35),
            testing::random_rotation(rng)};
    if (i % 2) s.batch.add(a, pa, b, pb);
    else s.batch.add(b, pb, a, pa);
  }
  QueryOptions o;
  o.level = QueryLevel::boolean;
  o.precision = Precision::float64;
  o.solver = resolve_solver(o.solver, o.level);
  o.closed_forms = false;
  o.threads = 2;
  PairResults got;
  collide(s.shapes, s.batch, o, got);
  const PairResults want = reference<double>(s, o, got, false);  // the plain double GJK's answers
  testing::expect_same_results(reference<double>(s, o, got), got, "certified reference");
  const PairResults in_float = in_float_precision(s, o);
  std::size_t colliding = 0, accepted = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(want.status[i], got.status[i]) << i;
    EXPECT_EQ(want.collide[i], got.collide[i]) << i;
    if (!got.collide[i]) continue;
    ++colliding;
    accepted += got.iterations[i] == in_float.iterations[i];
  }
  std::printf("[measured] sphere/capsule boolean double pairs: %zu, colliding: %zu, float answer proven: %zu\n",
              got.size(), colliding, accepted);
  EXPECT_GT(colliding, got.size() / 3);
  EXPECT_GT(accepted, colliding * 9 / 10);
  for (int threads : {1, 2}) {
    QueryOptions q = o;
    q.threads = threads;
    q.isa = InstructionSet::scalar;
    PairResults scalar, best;
    collide(s.shapes, s.batch, q, scalar);
    q.isa = resolve_instruction_set(InstructionSet::automatic);
    collide(s.shapes, s.batch, q, best);
    testing::expect_same_results(scalar, got, "scalar vs the certified run, threads " + std::to_string(threads));
    testing::expect_same_results(best, got, "best vs the certified run, threads " + std::to_string(threads));
  }
}

TEST(ExecutorGjkPairs, EveryInstructionSetGivesTheSameBits) {
  const Scene s = gjk_scene(3000, 13);
  // Boolean: a double query runs the float GJK and its double certificate (W float lanes per register, twice
  // double's), which must give the same bits as well, whatever the thread count.
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::witness}) {
    QueryOptions o;
    o.level = level;
    o.isa = InstructionSet::scalar;
    o.threads = 1;
    PairResults scalar, best, two;
    collide(s.shapes, s.batch, o, scalar);
    o.isa = resolve_instruction_set(InstructionSet::automatic);
    collide(s.shapes, s.batch, o, best);
    o.threads = 2;
    collide(s.shapes, s.batch, o, two);
    testing::expect_same_results(scalar, best, std::string("scalar vs this CPU's best, ") + to_string(level));
    testing::expect_same_results(best, two, std::string("1 vs 2 threads, ") + to_string(level));
  }
  QueryOptions o;
  o.level = QueryLevel::witness;
  PairResults best;
  collide(s.shapes, s.batch, o, best);
  for (std::size_t i = 0; i < best.size(); ++i) {
    const std::size_t r = i % 97;
    const bool made_invalid = r == 5 || r == 17 || r == 29 || r == 41;
    EXPECT_EQ(best.status[i] == Status::invalid_input, made_invalid) << i;
  }
}

}  // namespace
}  // namespace batchcol
