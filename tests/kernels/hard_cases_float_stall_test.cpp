// Hard cases, float GJK stalls: in single precision the simplex projection can lose a sliver simplex near a
// curved contact and GJK stops improving well above what float can certify. Such a stall used to be accepted as
// `converged` (2.9e-5 m off on a 0.6 m problem); now a float stall is accepted only within 2 precision floors and
// is otherwise solved again in double on the same cores (kernels/narrowphase.cpp). Asserted here: every float
// result reported `converged` is within max(tolerance, 2 floor) of the double reference, floor = 16 eps_f
// (bounding radii + centre distance), the README's float guarantee.
#include "support/hard_cases.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using testing::kEpsFloat;

/// The float floor of a pair: 16 eps_f (bounding radii + centre distance), as the engine computes it.
double float_floor(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  return 16 * kEpsFloat * (a.bounding_radius() + b.bounding_radius() + (pb.translation - pa.translation).norm());
}

QueryOptions float_options(Solver solver, double tolerance) {
  QueryOptions o = testing::hard_case_options(Precision::float32, QueryLevel::witness);
  o.solver = solver;
  o.tolerance = tolerance;
  return o;
}

QueryOptions double_reference() {
  QueryOptions o = testing::hard_case_options(Precision::float64, QueryLevel::witness, 1e-12);
  o.solver = Solver::gjk;
  return o;
}

// The pair of the report: 1e-6 m apart along x (cylinder radius 0.1 + ellipsoid x radius 0.1 + 1e-6).
TEST(HardCasesFloatStall, CylinderEllipsoidNesterovAt1e6IsWithinTwoFloors) {
  const Shape cylinder = Shape::cylinder(0.1, 0.2), ellipsoid = Shape::ellipsoid(0.1, 0.2, 0.05);
  const Pose pa = Pose::from_translation({0.3, -0.2, 0.1}), pb = Pose::from_translation({0.500001, -0.2, 0.1});
  const double gap = testing::run_pair(cylinder, pa, ellipsoid, pb, double_reference()).distance;
  EXPECT_NEAR(gap, 1e-6, 1e-12);
  const double bound = std::max(1e-7, 2 * float_floor(cylinder, pa, ellipsoid, pb));  // 2.6e-6 m
  for (Solver solver : {Solver::nesterov, Solver::polyak, Solver::gjk})
    for (QueryLevel level : {QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
      QueryOptions o = float_options(solver, 1e-7);
      o.level = level;
      const auto r = testing::run_pair(cylinder, pa, ellipsoid, pb, o);
      SCOPED_TRACE(std::string(to_string(solver)) + " " + to_string(level));
      EXPECT_EQ(r.status, Status::converged);  // was converged 2.9e-5 m off (Nesterov), 1.6e-5 (Polyak)
      if (r.collide && level < QueryLevel::penetration) continue;  // touching within the float floor: no distance
      EXPECT_LE(std::abs(r.distance - gap), bound) << r.distance;
    }
}

// Random curved-against-curved pairs (cylinder, cone, ellipsoid, capsule, sphere; not two point/segment cores, which
// have a closed form), random rotations, gaps 1e-7..1e-2 m placed along the reference normal, sizes 2-40 cm, every
// solver, tolerances 1e-7 (raised to the floor) and 1e-5.
TEST(HardCasesFloatStall, EveryConvergedFloatResultIsWithinTheToleranceOrTwoFloors) {
  testing::Rng rng(2026);
  const std::vector<ShapeType> curved = {ShapeType::cylinder, ShapeType::cone, ShapeType::ellipsoid, ShapeType::capsule,
                                         ShapeType::sphere};
  const auto point_or_segment = [](ShapeType t) { return t == ShapeType::capsule || t == ShapeType::sphere; };
  int results = 0, not_converged = 0;
  double worst = 0.0;  // error / max(tolerance, 2 floor)
  for (int trial = 0; trial < 1500; ++trial) {
    const ShapeType ta = curved[rng() % curved.size()];
    ShapeType tb = curved[rng() % curved.size()];
    if (point_or_segment(ta) && point_or_segment(tb)) tb = curved[rng() % 3];
    const Shape a = testing::random_shape(rng, ta), b = testing::random_shape(rng, tb);
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng), testing::random_rotation(rng)};
    const auto first = testing::run_pair(a, pa, b, pb, double_reference());
    ASSERT_GT(first.distance, 0.0);
    // Moving b along the normal by t changes the distance by exactly t (the separating plane moves with it).
    const double gap = std::pow(10.0, testing::uniform(rng, -7, -2));
    pb.translation += (gap - first.distance) * first.normal;
    const double reference = testing::run_pair(a, pa, b, pb, double_reference()).distance;
    const double floor = float_floor(a, pa, b, pb);
    for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak})
      for (double tolerance : {1e-7, 1e-5}) {
        const auto r = testing::run_pair(a, pa, b, pb, float_options(solver, tolerance));
        ++results;
        if (r.status != Status::converged) { ++not_converged; continue; }
        if (r.collide) {  // touching at the witness level: allowed only within the bound
          EXPECT_LE(reference, std::max(tolerance, 2 * floor)) << "trial " << trial;
          continue;
        }
        const double bound = std::max(tolerance, 2 * floor);
        SCOPED_TRACE("trial " + std::to_string(trial) + " " + to_string(ta) + "-" + to_string(tb) + " " +
                     to_string(solver) + " gap " + std::to_string(gap));
        EXPECT_LE(std::abs(r.distance - reference), bound);
        worst = std::max(worst, std::abs(r.distance - reference) / bound);
      }
  }
  // The fallback to double leaves (almost) every pair converged: reporting `degenerate` is not the fix.
  EXPECT_LE(not_converged, results / 1000);
  std::printf("[measured] float curved-curved, %d results: max error %.2f x max(tolerance, 2 floor), %d not converged\n",
              results, worst, not_converged);
}

// Cone-cone in the close regime (gaps 1e-4..1e-2 m, as `batchcol bench` and `batchcol accuracy`): the issue asks
// float for a relative error <= 1e-5, relative to the problem's size (bounding radii + centre distance, the report's
// `distance_relative_error_max`). The committed report missed it (1.02e-5): the same accepted float stalls (its
// worst pairs stalled with certificates of 4-14 floors). On these 1000 pairs the old rule gave 8.5e-4 (Nesterov);
// now every solver is within 2 floors = 32 eps_f = 3.8e-6 relative (measured 2.3e-6).
TEST(HardCasesFloatStall, ConeConeCloseRegimeRelativeErrorBelow1e5) {
  testing::Rng rng(7);
  double worst = 0.0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Shape a = testing::random_shape(rng, ShapeType::cone), b = testing::random_shape(rng, ShapeType::cone);
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng), testing::random_rotation(rng)};
    const auto first = testing::run_pair(a, pa, b, pb, double_reference());
    pb.translation += (std::pow(10.0, testing::uniform(rng, -4, -2)) - first.distance) * first.normal;
    const double reference = testing::run_pair(a, pa, b, pb, double_reference()).distance;
    const double size = a.bounding_radius() + b.bounding_radius() + (pb.translation - pa.translation).norm();
    for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      const auto r = testing::run_pair(a, pa, b, pb, float_options(solver, 1e-7));
      SCOPED_TRACE("trial " + std::to_string(trial) + " " + to_string(solver));
      EXPECT_EQ(r.status, Status::converged);
      const double relative = std::abs(r.distance - reference) / size;
      EXPECT_LE(relative, 32 * kEpsFloat);  // 2 floors; the 1e-5 with margin
      worst = std::max(worst, relative);
    }
  }
  std::printf("[measured] cone-cone close, float: max relative error %.3g (issue: <= 1e-5)\n", worst);
}

}  // namespace
}  // namespace batchcol
