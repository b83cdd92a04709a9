// GJK groups answered straight from the batch arrays (kernels::simd::gjk_pairs) give, pair by pair, the bits of the
// scalar reference: the relative pose as the executor computes it, kernels::solve_pair (scalar GJK), the output
// mapped to the world frame. Invalid pairs get invalid_input and NaN / 0 everywhere else.
#include "kernel_views.hpp"  // engine/src: pair_view, result_view
#include "kernels/math.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
Scene gjk_scene(std::size_t pairs, std::uint64_t seed) {
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

/// The scalar reference of every pair (every array full: NaN where the level computes nothing); pairs answered by a SIMD closed form take `got`'s values (they are not what
/// this test is about, and every other pair, sphere-box closed forms included, must match).
template <class T> PairResults reference(const Scene& s, const QueryOptions& o, const PairResults& got) {
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

template <class T> void expect_reference_bits(Precision precision) {
  const Scene s = gjk_scene(6000, precision == Precision::float64 ? 11 : 12);
  for (bool closed_forms : {false, true})
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness})
      for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
        QueryOptions o;
        o.level = level;
        o.solver = solver;
        o.precision = precision;
        // Off: every pair goes through GJK. On: the closed-form type pairs (sphere-box included) must still be
        // routed to their closed forms, and the rest to GJK.
        o.closed_forms = closed_forms;
        o.threads = 2;
        PairResults got;
        collide(s.shapes, s.batch, o, got);
        testing::expect_same_results(reference<T>(s, o, got), got,
                                     std::string(to_string(level)) + " " + to_string(solver) +
                                         (closed_forms ? " closed forms on" : " closed forms off"));
      }
}

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInDouble) { expect_reference_bits<double>(Precision::float64); }

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInFloat) { expect_reference_bits<float>(Precision::float32); }

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

TEST(ExecutorGjkPairs, EveryInstructionSetGivesTheSameBits) {
  const Scene s = gjk_scene(3000, 13);
  QueryOptions o;
  o.level = QueryLevel::witness;
  o.isa = InstructionSet::scalar;
  PairResults scalar, best;
  collide(s.shapes, s.batch, o, scalar);
  o.isa = resolve_instruction_set(InstructionSet::automatic);
  collide(s.shapes, s.batch, o, best);
  testing::expect_same_results(scalar, best, "scalar vs this CPU's best");
  for (std::size_t i = 0; i < best.size(); ++i) {
    const std::size_t r = i % 97;
    const bool made_invalid = r == 5 || r == 17 || r == 29 || r == 41;
    EXPECT_EQ(best.status[i] == Status::invalid_input, made_invalid) << i;
  }
}

}  // namespace
}  // namespace batchcol
