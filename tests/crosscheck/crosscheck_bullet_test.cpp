// Cross-check against Bullet's GJK/EPA (btGjkEpaSolver2::SignedDistance): 10,000 random pairs per shape type Bullet
// has as a convex shape (the type against every other such type, on both sides). First, the adapter's shapes are
// checked against batchcol's shape definitions through their support functions (margins, cone placement).
#include "crosscheck/crosscheck_runner.hpp"
#include "crosscheck/expectations.hpp"

#include <gtest/gtest.h>

#ifdef BATCHCOL_HAVE_BULLET
#include "peers/bullet_adapter.hpp"
#endif

namespace batchcol::crosscheck {
namespace {

#ifdef BATCHCOL_HAVE_BULLET

constexpr std::size_t kPairsPerType = 10000;
// Bullet's double-precision GJK stops at a relative duality gap of 1e-12, or when a support point comes within
// 1e-6 m of a recent one (GJK_DUPLICATED_EPS = 1e-12 on the squared distance), which leaves errors up to a few
// 1e-7 m on curved shapes: the agreement tolerance is 1e-6 m.
constexpr double kBulletAgreement = 1e-6;

std::vector<ShapeType> bullet_types() {
  std::vector<ShapeType> types;
  for (ShapeType t : testing::bounded_shape_types())
    if (bullet_supports(t)) types.push_back(t);
  return types;
}

TEST(BulletShapes, SupportMatchesBatchcolShapes) {
  ASSERT_TRUE(bullet_double_precision()) << "the cross-check expects Debian's float64 Bullet build";
  testing::Rng rng(0xb5);
  for (ShapeType type : bullet_types()) {
    for (int k = 0; k < 200; ++k) {
      const Shape s = testing::random_shape(rng, type);
      const Eigen::Vector3d d = testing::random_unit_vector(rng);
      EXPECT_NEAR(bullet_extent(s, d), testing::extent(s, d), 1e-12) << to_string(type);
    }
  }
}

class BulletCrossCheck : public ::testing::TestWithParam<ShapeType> {};

TEST_P(BulletCrossCheck, RandomPairsAgree) {
  const ShapeType type = GetParam();
  const CrossPairs pairs = make_pairs(0xb1000 + static_cast<int>(type), type, bullet_types(), kPairsPerType);
  RunConfig c;
  c.label = std::string("bullet ") + to_string(type);
  c.options.level = QueryLevel::penetration;
  c.options.tolerance = 1e-10;
  c.distance_tolerance = kBulletAgreement;
  c.peer_collide = bullet_signed_distance;
  c.peer_distance = bullet_signed_distance;
  const RunSummary s = run_crosscheck(pairs, c);
  print_summary(c.label, s);
  expect_batchcol_certified(s);
  expect_peer_settled(s);
}

INSTANTIATE_TEST_SUITE_P(ShapeTypes, BulletCrossCheck, ::testing::ValuesIn(bullet_types()),
                         [](const ::testing::TestParamInfo<ShapeType>& param) { return to_string(param.param); });

#else

TEST(BulletCrossCheck, SkippedWithoutBullet) {
  GTEST_SKIP() << "cross-check against Bullet skipped: install libbullet-dev";
}

#endif

}  // namespace
}  // namespace batchcol::crosscheck
