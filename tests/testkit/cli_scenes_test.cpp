// The scenes of `batchcol demo` and `batchcol rays` (tools/testkit/demo_scene.hpp, rays_scene.hpp), in-process:
// the same seed gives the same scene, and each keeps the promise its header makes (the demo's pairs overlap or are
// separated as constructed; the rays start on a sphere of radius 2 x half_extent and aim into the cube).
#include "testkit/demo_scene.hpp"
#include "testkit/rays_scene.hpp"

#include <batchcol/batchcol.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol::testkit {
namespace {

TEST(DemoScene, SameSeedSameScene) {
  const DemoScene a = make_demo_scene(300), b = make_demo_scene(300);
  ASSERT_EQ(a.pairs.size(), 300u);
  EXPECT_EQ(a.shapes.size(), b.shapes.size());
  EXPECT_EQ(a.pairs.shape_a, b.pairs.shape_a);
  EXPECT_EQ(a.pairs.shape_b, b.pairs.shape_b);
  EXPECT_EQ(a.pairs.translation_b.x, b.pairs.translation_b.x);
  EXPECT_EQ(a.pairs.rotation_a.w, b.pairs.rotation_a.w);
  const DemoScene c = make_demo_scene(300, 7);
  EXPECT_NE(a.pairs.translation_b.x, c.pairs.translation_b.x);
}

TEST(DemoScene, PairsOverlapOrAreSeparatedAsConstructed) {
  const DemoScene s = make_demo_scene(2000);
  ASSERT_EQ(s.overlapping, 1000u);  // every even pair
  QueryOptions o;
  o.level = QueryLevel::boolean;
  PairResults r;
  collide(s.shapes, s.pairs, o, r);
  for (std::size_t i = 0; i < s.pairs.size(); ++i) {
    ASSERT_EQ(r.status[i], Status::converged) << "pair " << i;
    EXPECT_EQ(r.collide[i] != 0, i % 2 == 0) << "pair " << i;
  }
}

TEST(RaysScene, SameSeedSameSceneAndRaysAimIntoTheCube) {
  RaysSceneSpec spec;
  spec.objects = 300;
  spec.hull_vertices = 40;
  const RaysScene a = make_rays_scene(spec), b = make_rays_scene(spec);
  ASSERT_EQ(a.handles.size(), 300u);
  EXPECT_GT(a.half_extent, 0.0);
  EXPECT_EQ(a.half_extent, b.half_extent);
  const RayBatch r = make_crossing_rays(500, a.half_extent, 3), q = make_crossing_rays(500, a.half_extent, 3);
  ASSERT_EQ(r.size(), 500u);
  EXPECT_EQ(r.direction.x, q.direction.x);
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Eigen::Vector3d o = r.origin[i], d = r.direction[i];
    EXPECT_NEAR(o.norm(), 2 * a.half_extent, 1e-9 * a.half_extent);
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
    // The target lies in the cube, inside the ball of radius sqrt(3) half_extent about the centre, seen from
    // 2 half_extent away under a half-angle of asin(sqrt(3) / 2) = 60 degrees: cos >= 0.5 towards the centre.
    EXPECT_GE(d.dot(-o.normalized()), 0.5 - 1e-12);
    EXPECT_TRUE(std::isinf(r.t_max[i]));
  }
}

}  // namespace
}  // namespace batchcol::testkit
