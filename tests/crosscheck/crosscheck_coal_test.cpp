// Cross-check against Coal (formerly HPP-FCL, built by ../shared/peers/build-coal.sh, found with
// -DCMAKE_PREFIX_PATH=/opt/coal): random pairs per bounded shape type (the type against every bounded type, on both
// sides), through coal::collide / coal::distance and through the direct GJK calls that `batchcol bench` times
// (plain and Nesterov, EPA for overlapping pairs). First, the adapter's shapes are checked against batchcol's shape
// definitions through their support functions (sizes, cone placement, inflation as swept-sphere radius).
#include "crosscheck/crosscheck_runner.hpp"
#include "crosscheck/expectations.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#ifdef BATCHCOL_HAVE_COAL
#include "peers/coal_adapter.hpp"
#endif

namespace batchcol::crosscheck {
namespace {

#ifdef BATCHCOL_HAVE_COAL

constexpr std::size_t kPairsPerType = 10000;
constexpr std::size_t kDirectPairsPerType = 3000;  // two more variants of the same GJK: fewer pairs each
// Coal's GJK stops when the distance to the best separating plane found is within tolerance * (1 + distance) of
// the current iterate (van den Bergen's criterion), and EPA when a face is within its tolerance of the support.
// At 1e-10 both stop well below the agreement tolerance on separated pairs; 1e-6 m bounds what is left on curved
// shapes, as for FCL and Bullet.
constexpr double kCoalTolerance = 1e-10;
constexpr double kCoalAgreement = 1e-6;
// Coal's EPA runs at 1e-6 at best (peers/coal_adapter.hpp), so its depths differ from batchcol's by more than the
// agreement tolerance on some pairs, and the certificates prove it: measured up to 1.7% of the overlapping
// ellipsoid pairs (median 3e-6 m, max 1.1e-3 m), 0-0.6% on the other types, with std:: distributions; 2.5% on
// nesterov ellipsoid pairs with the portable generator's draws. Separated distances never disagreed.
constexpr double kCoalMaxPeerWrong = 0.03;

/// Coal 3.0's sphereCylinderDistance (src/narrowphase/details.h), which coal::distance runs for sphere-cylinder
/// pairs, returns the radial depth dPS - r_sphere - r_cylinder whenever the sphere's centre is between the caps, even
/// when a cap is nearer: too deep when the centre is inside the cylinder closer to a cap than to the side.
const char* coal_sphere_cylinder_bug(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  const bool sphere_a = a.type == ShapeType::sphere && b.type == ShapeType::cylinder;
  const bool sphere_b = b.type == ShapeType::sphere && a.type == ShapeType::cylinder;
  if (!sphere_a && !sphere_b) return nullptr;
  const Pose& sphere = sphere_a ? pa : pb;
  const Pose& cylinder = sphere_a ? pb : pa;
  const Eigen::Vector3d& size = (sphere_a ? b : a).size;  // (radius, half_length)
  const Eigen::Vector3d c = cylinder.rotation.conjugate() * (sphere.translation - cylinder.translation);
  const bool inside = std::abs(c.z()) < size.y() && c.head<2>().norm() < size.x();
  return inside ? "Coal sphereCylinderDistance: radial depth for a sphere centre inside the cylinder" : nullptr;
}

QueryOptions reference_query() {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.tolerance = 1e-10;
  return o;
}

TEST(CoalShapes, SupportMatchesBatchcolShapes) {
  testing::Rng rng(0xc0a1);
  for (ShapeType type : testing::bounded_shape_types()) {
    for (int k = 0; k < 200; ++k) {
      Shape s = testing::random_shape(rng, type);
      if (k % 2 == 1) s = s.inflated(0.01 * (1 + k % 5));  // swept-sphere radius on every type
      const Eigen::Vector3d d = testing::random_unit_vector(rng);
      EXPECT_NEAR(coal_extent(s, d), testing::extent(s, d), 1e-12) << to_string(type) << " inflation " << s.inflation;
    }
  }
}

class CoalCrossCheck : public ::testing::TestWithParam<ShapeType> {};

TEST_P(CoalCrossCheck, RandomPairsAgree) {
  const ShapeType type = GetParam();
  const CrossPairs pairs = make_pairs(0xc0a1000 + static_cast<int>(type), type, testing::bounded_shape_types(),
                                      kPairsPerType);
  RunConfig c;
  c.label = std::string("coal ") + to_string(type);
  c.options = reference_query();
  c.distance_tolerance = kCoalAgreement;
  c.peer_collide = coal_collide;
  c.peer_distance = [](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return coal_distance(a, pa, b, pb, kCoalTolerance);
  };
  c.known_peer_bug = coal_sphere_cylinder_bug;
  const RunSummary s = run_crosscheck(pairs, c);
  print_summary(c.label, s);
  expect_batchcol_certified(s);
  expect_peer_settled(s, kCoalMaxPeerWrong);
}

INSTANTIATE_TEST_SUITE_P(ShapeTypes, CoalCrossCheck, ::testing::ValuesIn(testing::bounded_shape_types()),
                         [](const ::testing::TestParamInfo<ShapeType>& param) { return to_string(param.param); });

struct DirectCase {
  ShapeType type;
  CoalGjkVariant variant;
};

void PrintTo(const DirectCase& d, std::ostream* os) { *os << to_string(d.variant) << " " << to_string(d.type); }

class CoalDirectGjkCrossCheck : public ::testing::TestWithParam<DirectCase> {};

TEST_P(CoalDirectGjkCrossCheck, RandomPairsAgree) {
  const DirectCase d = GetParam();
  const CrossPairs pairs = make_pairs(0xc0a2000 + 16 * static_cast<int>(d.variant) + static_cast<int>(d.type), d.type,
                                      testing::bounded_shape_types(), kDirectPairsPerType);
  RunConfig c;
  c.label = std::string("coal direct ") + to_string(d.variant) + " " + to_string(d.type);
  c.options = reference_query();
  c.distance_tolerance = kCoalAgreement;
  c.peer_collide = [v = d.variant](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return coal_gjk_collide(a, pa, b, pb, v);
  };
  c.peer_distance = [v = d.variant](const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    return coal_gjk_distance(a, pa, b, pb, v, kCoalTolerance, true);
  };
  const RunSummary s = run_crosscheck(pairs, c);
  print_summary(c.label, s);
  expect_batchcol_certified(s);
  expect_peer_settled(s, kCoalMaxPeerWrong);
}

std::vector<DirectCase> direct_cases() {
  std::vector<DirectCase> cases;
  for (CoalGjkVariant v : {CoalGjkVariant::plain, CoalGjkVariant::nesterov})
    for (ShapeType t : testing::bounded_shape_types()) cases.push_back({t, v});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(ShapeTypes, CoalDirectGjkCrossCheck, ::testing::ValuesIn(direct_cases()),
                         [](const ::testing::TestParamInfo<DirectCase>& param) {
                           return std::string(to_string(param.param.variant)) + "_" + to_string(param.param.type);
                         });

#else

TEST(CoalCrossCheck, SkippedWithoutCoal) {
  GTEST_SKIP() << "cross-check against Coal skipped: build it with ../shared/peers/build-coal.sh and configure with "
                  "-DCMAKE_PREFIX_PATH=/opt/coal";
}

#endif

}  // namespace
}  // namespace batchcol::crosscheck
