// GJK groups answered straight from the batch arrays (kernels::simd::gjk_pairs) give, pair by pair, the bits of the
// scalar reference: the relative pose as the executor computes it, kernels::solve_pair (scalar GJK), the output
// mapped to the world frame. Invalid pairs get invalid_input and NaN / 0 everywhere else.
#include "kernels/math.hpp"
#include "kernels/narrowphase.hpp"
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

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
    Pose pa{Eigen::Vector3d::Random() * 3.0, testing::random_rotation(rng)};
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

template <class T> PairResults reference(const Scene& s, const QueryOptions& o) {
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
    const Eigen::Matrix3d Ra = kernels::rotation_matrix(qa[0], qa[1], qa[2], qa[3]);
    kernels::RelativePose X;
    X.R = kernels::transposed_product(Ra, kernels::rotation_matrix(qb[0], qb[1], qb[2], qb[3]));
    X.t = kernels::mul_transposed<double>(Ra, tb - ta);
    const kernels::PairOutput<T> p = kernels::solve_pair<T>(s.shapes[b.shape_a[i]], s.shapes[b.shape_b[i]], X,
                                                             Eigen::Vector3d::Constant(kNan), o);
    r.status[i] = p.status;
    r.collide[i] = p.collide ? 1 : 0;
    r.iterations[i] = p.iterations;
    r.distance[i] = double(p.distance);
    if (o.level >= QueryLevel::witness) {
      r.witness_a.set(i, kernels::mul<double>(Ra, p.witness_a.template cast<double>()) + ta);
      r.witness_b.set(i, kernels::mul<double>(Ra, p.witness_b.template cast<double>()) + ta);
      r.normal.set(i, kernels::mul<double>(Ra, p.normal.template cast<double>()));
    }
    r.direction.set(i, kernels::mul<double>(Ra, p.direction.template cast<double>()));
  }
  return r;
}

template <class T> void expect_reference_bits(Precision precision) {
  const Scene s = gjk_scene(6000, precision == Precision::float64 ? 11 : 12);
  std::size_t checked = 0;
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness})
    for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      QueryOptions o;
      o.level = level;
      o.solver = solver;
      o.precision = precision;
      o.closed_forms = false;  // every pair of these types goes through GJK, so every pair is compared
      o.threads = 2;
      PairResults got;
      collide(s.shapes, s.batch, o, got);
      testing::expect_same_results(reference<T>(s, o), got,
                                   std::string(to_string(level)) + " " + to_string(solver));
      checked += got.size();
    }
  EXPECT_EQ(checked, 9u * 6000u);
}

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInDouble) { expect_reference_bits<double>(Precision::float64); }

TEST(ExecutorGjkPairs, EveryPairHasTheScalarReferenceBitsInFloat) { expect_reference_bits<float>(Precision::float32); }

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
