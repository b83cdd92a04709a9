// Cross-check against FCL 0.7: 10,000 random pairs per shape type (the type against every bounded type, on both
// sides), plus halfspaces against every bounded type. Booleans come from fcl::collide, distances from
// fcl::distance with signed distance enabled; see crosscheck_runner.hpp for how disagreements are settled.
#include "crosscheck/crosscheck_runner.hpp"
#include "crosscheck/expectations.hpp"

#include <gtest/gtest.h>

#ifdef BATCHCOL_HAVE_FCL
#include "peers/fcl_adapter.hpp"
#endif

namespace batchcol::crosscheck {
namespace {

#ifdef BATCHCOL_HAVE_FCL

constexpr std::size_t kPairsPerType = 10000;
// Solver choice, measured on these pairs: GST_INDEP (FCL's port of Bullet's GJK) is tighter on most pairs (p99
// ~8e-11 m) but returns distances up to 2 cm too large on ~0.3% of the pairs with polytopes (proven by the
// certificates); GST_LIBCCD never failed, its worst error being ~5e-7 m. libccd is the more accurate reference.
constexpr FclSolver kSolver = FclSolver::libccd;
// distance_tolerance: libccd stops when an iteration gains less than this. That is not a certificate: on curved
// shapes it stops ~1e-8..5e-7 m from the distance, hence the agreement tolerance of 1e-6 m.
constexpr double kFclStopTolerance = 1e-12;
constexpr double kFclAgreement = 1e-6;

QueryOptions reference_query() {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.tolerance = 1e-10;
  return o;
}

/// FCL 0.7 coneHalfspaceIntersect (primitive_shape_algorithm/halfspace-inl.h) tests `cosa < tolerance` where the
/// cylinder version tests `std::abs(cosa) < tolerance`: whenever the cone's axis points away from the halfspace
/// normal it treats the cone as a sphere of the cone's radius around its centre (wrong boolean and depth).
const char* fcl_cone_halfspace_bug(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  const bool cone_a = a.type == ShapeType::cone, cone_b = b.type == ShapeType::cone;
  if (!((cone_a && b.type == ShapeType::halfspace) || (cone_b && a.type == ShapeType::halfspace))) return nullptr;
  const Pose& cone_pose = cone_a ? pa : pb;
  const Pose& plane_pose = cone_a ? pb : pa;
  const Eigen::Vector3d normal = plane_pose.rotation * (cone_a ? b : a).size;
  const double cosa = (cone_pose.rotation * Eigen::Vector3d::UnitZ()).dot(normal);
  return cosa < 1e-6 ? "FCL coneHalfspaceIntersect: cone axis away from the plane normal" : nullptr;
}

std::string label_for(const char* what) { return std::string("fcl/") + to_string(kSolver) + " " + what; }

class FclCrossCheck : public ::testing::TestWithParam<ShapeType> {};

TEST_P(FclCrossCheck, RandomPairsAgree) {
  const ShapeType type = GetParam();
  const CrossPairs pairs = make_pairs(0xfc1000 + static_cast<int>(type), type, testing::bounded_shape_types(),
                                      kPairsPerType);
  RunConfig c;
  c.label = label_for(to_string(type));
  c.options = reference_query();
  c.distance_tolerance = kFclAgreement;
  c.peer_collide = [](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return fcl_collide(a, pa, b, pb, kSolver, false);
  };
  c.peer_distance = [](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return fcl_distance(a, pa, b, pb, kSolver, kFclStopTolerance);
  };
  // FCL 0.7's libccd EPA (signed distance of overlapping pairs) aborts on an internal assertion for some pairs
  // (ComputeVisiblePatch: isOutsidePolytopeFace); the brief compares distances of separated pairs only anyway.
  c.peer_depths = false;
  const RunSummary s = run_crosscheck(pairs, c);
  print_summary(c.label, s);
  expect_batchcol_certified(s);
  expect_peer_settled(s);
}

INSTANTIATE_TEST_SUITE_P(ShapeTypes, FclCrossCheck, ::testing::ValuesIn(testing::bounded_shape_types()),
                         [](const ::testing::TestParamInfo<ShapeType>& param) { return to_string(param.param); });

// FCL has analytic halfspace tests (with exact depths) but no halfspace distance; batchcol's distances are checked
// against the exact value the sampler placed them at (the certificate is exact for halfspaces too).
TEST(FclCrossCheckHalfspace, RandomPairsAgree) {
  const CrossPairs pairs = make_pairs(0xfc1fff, ShapeType::halfspace, testing::bounded_shape_types(),
                                      kPairsPerType);
  RunConfig c;
  c.label = label_for("halfspace");
  c.options = reference_query();
  c.distance_tolerance = 1e-9;
  c.peer_collide = [](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return fcl_collide(a, pa, b, pb, kSolver, false);
  };
  c.peer_distance = [](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return fcl_collide(a, pa, b, pb, kSolver, true);  // depth of overlapping pairs only
  };
  c.known_peer_bug = fcl_cone_halfspace_bug;
  const RunSummary s = run_crosscheck(pairs, c);
  print_summary(c.label, s);
  expect_batchcol_certified(s);
  expect_peer_settled(s);
  EXPECT_LE(s.certified_gap.max(), 1e-9) << "halfspace distances are exact";
  EXPECT_LE(s.depth_gap.max(), 1e-9) << "halfspace depths are exact";
  EXPECT_LE(s.depth_diff.max(), 1e-9) << "FCL's analytic halfspace depths are exact too (outside its cone bug)";
  for (std::size_t i = 0; i < pairs.batch.size(); i += 97) {
    const Shape& a = pairs.shapes[pairs.batch.shape_a[i]];
    const Shape& b = pairs.shapes[pairs.batch.shape_b[i]];
    const auto r = testing::run_pair(a, pairs.batch.pose_a(i), b, pairs.batch.pose_b(i), reference_query());
    EXPECT_NEAR(r.distance, pairs.plane_gap[i], 1e-9) << "pair " << i;
  }
}

#else

TEST(FclCrossCheck, SkippedWithoutFcl) { GTEST_SKIP() << "cross-check against FCL skipped: install libfcl-dev"; }

#endif

}  // namespace
}  // namespace batchcol::crosscheck
