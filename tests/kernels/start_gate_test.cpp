// The start gate (kernels/simd/wide_gjk_start_gate.inl, its twin tests/support/reference_start_gate.hpp): where it
// says that a pair's cores overlap, start() computes no closed-form start candidate. That is only free of effect
// if no candidate could have been kept there; this test checks it, and that the gate does fire on overlapping
// pairs (else it would save nothing). The lanes are bitwise the reference with the gate (WideGjk tests).
#include "kernels/narrowphase.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"
#include "support/reference_gjk.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <string>

namespace batchcol {
namespace {

using testing::Rng;

/// The candidate the reference's gjk() would compute for the pair (its type's family), or false.
bool candidate_kept(const kernels::MinkowskiDifference<double>& D) {
  kernels::SupportPoint<double> p;
  const ShapeType a = D.A->type, b = D.B->type;
  if (kernels::rim_start_pair(a, b)) return test_reference::rim_candidate(D, p);
  if (kernels::box_ellipsoid_pair(a, b)) return test_reference::box_ellipsoid_candidate(D, p);
  if (kernels::box_round_pair(a, b)) return test_reference::box_round_candidate(D, p);
  if (kernels::round_ellipsoid_pair(a, b)) return test_reference::round_ellipsoid_candidate(D, p);
  return false;
}

}  // namespace

/// Pairs of every start-candidate type, B moved from A's centre along a random direction u by a fraction f in
/// [0.3, 1.05] of the cores' joint extent along u (the bench's overlap regime moves B's centre out from A's the
/// same way): deep and shallow overlaps and near misses. Wherever the gate fires, GJK must find an overlap and
/// the pair's candidate must be dropped (its separation test); and the gate must fire on a good share of the
/// overlapping pairs (measured: 2136 of 2886 overlapping pairs, 83 of 107 with f > 0.9; the bounds are about
/// half that; a gate made unsound, every core grown by 1.3, fails 908 checks).
TEST(StartGate, FiresOnlyWhereNoCandidateCanBeKept) {
  Rng rng(2711);
  QueryOptions opt;
  opt.level = QueryLevel::penetration;
  opt.tolerance = 1e-9;
  const ShapeType types[] = {ShapeType::box, ShapeType::cylinder, ShapeType::cone, ShapeType::ellipsoid,
                             ShapeType::capsule, ShapeType::sphere};
  int overlapping = 0, gated = 0, shallow = 0, shallow_gated = 0;
  for (const ShapeType ta : types) {
    for (const ShapeType tb : types) {
      if (!kernels::start_candidate_pair(ta, tb)) continue;
      for (int trial = 0; trial < 200; ++trial) {
        std::deque<OwnedShapeView> keep;
        keep.emplace_back(testing::random_shape(rng, ta, 0.01, 0.2));
        keep.emplace_back(testing::random_shape(rng, tb, 0.01, 0.2));
        kernels::RelativePose X;
        X.R = testing::random_rotation(rng).toRotationMatrix();
        X.t.setZero();
        const Eigen::Vector3d u = testing::random_unit_vector(rng);
        const Eigen::Vector3d none = Eigen::Vector3d::Constant(std::nan(""));
        const auto s0 = kernels::setup_pair<double>(keep[0].view, keep[1].view, X, none, opt);
        const double extent = s0.difference().support(u).w.dot(u);  // h_A(u) + h_B(-u)
        const double f = testing::uniform(rng, 0.3, 1.05);
        X.t = f * extent * u;
        const auto s = kernels::setup_pair<double>(keep[0].view, keep[1].view, X, none, opt);
        if (s.done) continue;  // a closed form answers it
        const auto D = s.difference();
        const bool gate = test_reference::cores_overlap(D, D.support(-s.initial_direction));
        const auto r = test_reference::gjk(D, s.initial_direction, s.params);
        const bool overlap = r.status == kernels::GjkStatus::overlap;
        overlapping += overlap ? 1 : 0;
        gated += gate ? 1 : 0;
        shallow += overlap && f > 0.9 ? 1 : 0;
        shallow_gated += gate && f > 0.9 ? 1 : 0;
        if (!gate) continue;
        SCOPED_TRACE(std::string(to_string(ta)) + "-" + to_string(tb) + " trial " + std::to_string(trial));
        EXPECT_TRUE(overlap) << "the gate proved an overlap GJK did not find";
        EXPECT_FALSE(candidate_kept(D)) << "the gate skipped a candidate that would have been kept";
      }
    }
  }
  EXPECT_GE(gated, overlapping / 2) << gated << " gated of " << overlapping << " overlapping pairs";
  EXPECT_GE(shallow_gated, shallow / 4) << shallow_gated << " gated of " << shallow << " shallow overlaps (f > 0.9)";
  std::printf("start gate: %d of %d overlapping pairs gated, %d of %d with f > 0.9\n", gated, overlapping,
              shallow_gated, shallow);
}

}  // namespace batchcol
