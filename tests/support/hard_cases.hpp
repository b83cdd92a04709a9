// Helpers shared by the hard-case tests (tests/kernels/hard_cases*_test.cpp): their query options, the sanity
// checks every result must pass, and the placement of two shapes at an exact signed gap along a world axis.
#pragma once

#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol::testing {

/// Single precision's unit roundoff: float bounds are multiples of eps_f times the problem's scale.
constexpr double kEpsFloat = 1.1920928955078125e-7;
constexpr double kEpsDouble = 2.220446049250313e-16;
constexpr double epsilon(Precision p) { return p == Precision::float64 ? kEpsDouble : kEpsFloat; }

inline const char* precision_name(Precision p) { return p == Precision::float64 ? "double" : "float"; }

inline const Eigen::Quaterniond kIdentity = Eigen::Quaterniond::Identity();

/// GJK and EPA only (closed forms off), generous budgets, Nesterov (the README's hard-case table is measured with
/// it; GJK and Polyak go through AnalyticDistance* and HardCasesFloatStall*, which run every solver). Double runs at `double_tolerance`; float asks for
/// 1e-7 m, which the engine raises to its floor 16 eps_f (radii + centre distance), ~1e-6 m for 0.6 m problems.
inline QueryOptions hard_case_options(Precision precision, QueryLevel level = QueryLevel::penetration,
                                      double double_tolerance = 1e-12) {
  QueryOptions o;
  o.level = level;
  o.precision = precision;
  o.tolerance = precision == Precision::float64 ? double_tolerance : 1e-7;
  o.max_iterations = 1000;
  o.epa_max_iterations = 2000;
  o.closed_forms = false;
  o.solver = Solver::nesterov;
  return o;
}

/// Converged, no NaN and no sentinel wherever `level` computes a value, |distance| below `max_abs`, a unit normal,
/// and wb - wa = d n within `identity_bound`. Below the penetration level a colliding (touching) pair has no
/// distance: NaN there is the documented "not computed".
inline void expect_sane(const SingleResult& r, QueryLevel level, double identity_bound, double max_abs = 10.0) {
  EXPECT_EQ(r.status, Status::converged);
  if (level == QueryLevel::boolean || (r.collide && level < QueryLevel::penetration)) return;
  ASSERT_TRUE(std::isfinite(r.distance));
  EXPECT_LT(std::abs(r.distance), max_abs);
  if (level < QueryLevel::witness) return;
  ASSERT_TRUE(r.witness_a.allFinite() && r.witness_b.allFinite() && r.normal.allFinite());
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-6);
  EXPECT_LE((r.witness_b - r.witness_a - r.distance * r.normal).norm(), identity_bound);
}

/// Places b at signed gap `gap` from a along the world direction Q x, both turned by the common rotation Q and then
/// by their own rotations ra, rb, and moved to T; `lateral` offsets b across x (in Q's frame). The extents along x
/// make the answer exactly `gap` when separated, and the depth exactly -gap for contacts whose shortest way out is
/// x (flat faces, or a vertex/edge/curved tip into a face much larger than the overlap).
inline SingleResult beside(const Shape& a, const Eigen::Quaterniond& ra, const Shape& b, const Eigen::Quaterniond& rb,
                           double gap, const Eigen::Vector3d& T, const Eigen::Quaterniond& Q, const QueryOptions& o,
                           const Eigen::Vector3d& lateral = Eigen::Vector3d::Zero()) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const double L = extent(a, ra.inverse() * x) + extent(b, rb.inverse() * -x) + gap;
  return run_pair(a, Pose{T, Q * ra}, b, Pose{T + Q * (L * x + lateral), Q * rb}, o);
}

}  // namespace batchcol::testing
