// Per-shape ray kernels (kernels/rays/) against an independent reference: sphere tracing on a 1-Lipschitz lower bound
// of each shape's signed distance (tests/support/ray_reference.hpp). Every type, with and without inflation; rays
// from outside and inside, all directions, finite and infinite t_max. Exact kernels must agree to ~1e-9 m; the GJK
// ray cast (inflated shapes) must return a lower bound of t whose point lies within the tolerance of the surface.
#include "shape_table_access.hpp"  // engine/src: hull_view, OwnedShapeView
#include "support/generators.hpp"
#include "support/ray_reference.hpp"

#include "kernels/rays/ray_shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;
namespace kr = kernels::rays;

struct Ray {
  Eigen::Vector3d o, d;
  double t_max;
};

// Origins in a 6 m cube (some inside the shape), unit directions aimed at a point near the shape (most rays hit), a
// quarter with a finite t_max.
std::vector<Ray> random_rays(Rng& rng, int n, double reach) {
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    Ray r;
    r.o = testing::random_vector(rng, 3.0);  // one draw per statement: portable, whatever the evaluation order
    if (i % 7 == 0) r.o *= 0.05;  // near the centre: inside most shapes
    const Eigen::Vector3d target = testing::random_vector(rng, reach);
    r.d = (target - r.o).normalized();
    if (i % 11 == 0) r.d = testing::random_unit_vector(rng);
    r.t_max = i % 4 == 0 ? uniform(rng, 0.5, 6.0) : std::numeric_limits<double>::infinity();
    rays.push_back(r);
  }
  return rays;
}

struct Tally {
  int compared = 0, skipped = 0;
  double max_t_error = 0.0;
};

// Checks one shape with `n` rays; returns the tally (the caller asserts enough rays were compared).
Tally check_shape(const Shape& shape, int n, std::uint64_t seed, double tolerance = 1e-9) {
  Rng rng(seed);
  kr::HullPlanes<double> planes;
  if (shape.type == ShapeType::convex) planes = kr::make_hull_planes<double>(hull_view(*shape.hull));
  const OwnedShapeView view(shape);
  const kr::RayShape<double> prepared = kr::make_ray_shape<double>(view.view, &planes);
  const bool gjk = kr::uses_ray_gjk(view.view);
  kr::RayGjkSettings settings;
  settings.tolerance = tolerance;
  settings.max_iterations = 200;
  Tally tally;
  const double reach = shape.type == ShapeType::halfspace ? 2.0 : 1.1 * shape.bounding_radius();
  for (const Ray& r : random_rays(rng, n, reach)) {
    const kr::LocalHit<double> h = kr::ray_local(prepared, r.o, r.d, r.t_max, settings);
    const testing::TraceResult ref = testing::sphere_trace(shape, r.o, r.d, r.t_max);
    if (!ref.converged) {
      ++tally.skipped;
      continue;
    }
    SCOPED_TRACE(::testing::Message() << to_string(shape.type) << " inflation " << shape.inflation << " o "
                                      << r.o.transpose() << " d " << r.d.transpose() << " t_max " << r.t_max);
    EXPECT_EQ(h.status, kr::LocalStatus::converged);
    if (h.hit != ref.hit) {
      // Only a ray that grazes the surface may disagree, and only one way: the kernel reports a tangent hit (its
      // normal orthogonal to the ray) that sphere tracing steps over. A kernel miss where the reference hits fails.
      EXPECT_TRUE(h.hit) << "reference hit at t " << ref.t;
      EXPECT_LT(std::abs(h.normal.dot(r.d)), 1e-6) << "kernel t " << h.t;
      ++tally.skipped;
      continue;
    }
    ++tally.compared;
    if (!h.hit) continue;
    EXPECT_NEAR(h.normal.norm(), 1.0, 1e-12);
    const double err = h.t - ref.t;
    tally.max_t_error = std::max(tally.max_t_error, std::abs(err));
    const Eigen::Vector3d p = r.o + h.t * r.d;
    if (h.t == 0.0) {  // the origin is inside (the reference starts inside too: both at t = 0)
      EXPECT_EQ(ref.t, 0.0);
      EXPECT_LE(testing::shape_phi(shape, r.o), 1e-12);
      EXPECT_EQ(h.normal, (-r.d / r.d.norm()).eval());
      continue;
    }
    if (gjk) {
      // Certified: the point is outside (phi >= 0 up to rounding) and within the tolerance of the shape; t never
      // passes the exact hit (the reference stops 1e-12 before it).
      EXPECT_GE(testing::shape_phi(shape, p), -1e-12);
      EXPECT_LE(testing::shape_phi(shape, p), tolerance * 1.001);
      EXPECT_LE(h.t, ref.t + 1e-9);
      continue;
    }
    // The reference stops where phi <= 1e-12, i.e. up to 1e-12 / cos(angle to the normal) before the surface (the
    // floor only avoids a division by zero: grazing rays, cosines below 1e-3, do occur).
    const double cosine = std::abs(h.normal.dot(r.d));
    EXPECT_NEAR(h.t, ref.t, 1e-9 + 1e-12 / std::max(cosine, 1e-9)) << "cosine " << cosine;
    if (shape.type != ShapeType::triangle) {
      // The normal is outward: a step along it leaves the solid (edges and corners included: any normal of the
      // normal cone passes this test), and the surface is at phi = 0.
      EXPECT_LE(std::abs(testing::shape_phi(shape, p)), 1e-9);
      EXPECT_GT(testing::shape_phi(shape, p + 1e-6 * h.normal), 0.0);
    }
  }
  return tally;
}

class RayShapes : public ::testing::TestWithParam<ShapeType> {};

TEST_P(RayShapes, ExactKernelMatchesSphereTracing) {
  Rng rng(1234 + static_cast<int>(GetParam()));
  for (int k = 0; k < 4; ++k) {
    const Shape shape = testing::random_shape(rng, GetParam(), 0.3, 1.5);
    const Tally t = check_shape(shape, 1500, 99 + k);
    EXPECT_GE(t.compared, 1400) << "skipped " << t.skipped;
  }
}

TEST_P(RayShapes, InflatedShapeMatchesSphereTracing) {
  Rng rng(777 + static_cast<int>(GetParam()));
  for (int k = 0; k < 3; ++k) {
    const Shape shape = testing::random_shape(rng, GetParam(), 0.3, 1.2).inflated(uniform(rng, 0.05, 0.3));
    const Tally t = check_shape(shape, 800, 5 + k);
    EXPECT_GE(t.compared, 740) << "skipped " << t.skipped;
    std::ostringstream error;
    error << std::scientific << t.max_t_error;
    ::testing::Test::RecordProperty("max_t_error_" + std::to_string(k), error.str());
  }
}

INSTANTIATE_TEST_SUITE_P(AllTypes, RayShapes,
                         ::testing::Values(ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::cylinder,
                                           ShapeType::cone, ShapeType::ellipsoid, ShapeType::convex,
                                           ShapeType::triangle),
                         [](const ::testing::TestParamInfo<ShapeType>& info) { return to_string(info.param); });

TEST(RayShapesHalfspace, ExactAndInflated) {
  const Shape plane = Shape::halfspace(Eigen::Vector3d(0.3, -0.4, 0.866).normalized(), 0.2);
  EXPECT_GE(check_shape(plane, 1000, 3).compared, 990);
  EXPECT_GE(check_shape(plane.inflated(0.25), 1000, 4).compared, 990);
}

TEST(RayShapesClosedForm, SphereBoxAndInsideConvention) {
  const kr::RayGjkSettings settings;
  kr::HullPlanes<double> none;
  const auto cast = [&](const Shape& s, Eigen::Vector3d o, Eigen::Vector3d d, double t_max) {
    const OwnedShapeView view(s);
    return kr::ray_local(kr::make_ray_shape<double>(view.view, &none), o, d, t_max, settings);
  };
  // A unit sphere from 5 m away along x with a direction of length 2: t is in units of |d|.
  kr::LocalHit<double> h = cast(Shape::sphere(1.0), {-5, 0, 0}, {2, 0, 0}, 10.0);
  ASSERT_TRUE(h.hit);
  EXPECT_DOUBLE_EQ(h.t, 2.0);
  EXPECT_EQ(h.normal, Eigen::Vector3d(-1, 0, 0));
  // t_max just short of the hit: no hit; exactly at it: hit.
  EXPECT_FALSE(cast(Shape::sphere(1.0), {-5, 0, 0}, {2, 0, 0}, 1.999).hit);
  EXPECT_TRUE(cast(Shape::sphere(1.0), {-5, 0, 0}, {2, 0, 0}, 2.0).hit);
  // Pointing away: no hit. From inside: t = 0, normal -d/|d|.
  EXPECT_FALSE(cast(Shape::sphere(1.0), {-5, 0, 0}, {-1, 0, 0}, INFINITY).hit);
  h = cast(Shape::box(1, 2, 3), {0.5, 0, 0}, {0, 0, 4}, INFINITY);
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.t, 0.0);
  EXPECT_EQ(h.normal, Eigen::Vector3d(0, 0, -1));
  // A box face hit head-on, and a ray parallel to a face (d_x = 0) outside its slab misses.
  h = cast(Shape::box(1, 2, 3), {0, 0, 10}, {0, 0, -1}, INFINITY);
  EXPECT_EQ(h.t, 7.0);
  EXPECT_EQ(h.normal, Eigen::Vector3d(0, 0, 1));
  EXPECT_FALSE(cast(Shape::box(1, 2, 3), {1.5, 0, 10}, {0, 0, -1}, INFINITY).hit);
  // A sphere far away (|o| = 1e6 m): the closest-point form keeps the hit exact to rounding.
  h = cast(Shape::sphere(0.5), {1e6, 0.3, 0}, {-1, 0, 0}, INFINITY);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 1e6 - std::sqrt(0.25 - 0.09), 1e-9);
}

TEST(RayShapesClosedForm, FloatKernelsAgreeWithDouble) {
  Rng rng(31);
  for (ShapeType type : testing::bounded_shape_types()) {
    const Shape s = testing::random_shape(rng, type, 0.3, 1.2);
    kr::HullPlanes<double> pd;
    kr::HullPlanes<float> pf;
    if (type == ShapeType::convex)
      pd = kr::make_hull_planes<double>(hull_view(*s.hull)), pf = kr::make_hull_planes<float>(hull_view(*s.hull));
    const OwnedShapeView view(s);
    const auto sd = kr::make_ray_shape<double>(view.view, &pd);
    const auto sf = kr::make_ray_shape<float>(view.view, &pf);
    int agree = 0, total = 0;
    for (const Ray& r : random_rays(rng, 500, 1.0)) {
      const auto hd = kr::ray_local(sd, r.o, r.d, r.t_max, {});
      const auto hf = kr::ray_local<float>(sf, r.o.cast<float>(), r.d.cast<float>(), float(r.t_max), {});
      ++total;
      if (hd.hit != hf.hit) continue;  // grazing rays may flip in float
      ++agree;
      // Float's position error moves t by that over the cosine of the incidence angle. 4e-5 relative: the float
      // cone kernel was seen 2.9e-5 off at a cosine of 0.98 (t = 3.39) on the portable generator's draws.
      const double cosine = std::abs(hd.normal.dot(r.d));
      if (hd.hit) { EXPECT_NEAR(hf.t, hd.t, 4e-5 * (1 + hd.t) / std::max(cosine, 0.05)) << to_string(type) << " cosine " << cosine; }
    }
    EXPECT_GE(agree, total - 5) << to_string(type);
  }
}

}  // namespace
}  // namespace batchcol

namespace batchcol {
namespace {

// Hulls of kHullWalkMinFaces faces or more go through the polar walk (ray_hull_walk.hpp): it must give the same hit,
// the same t up to the choice between faces whose t tie in rounding, and agree with sphere tracing. One hull has
// coplanar triangles (a cube: qhull triangulates its squares), which the walk merges into facets.
TEST(RayHullWalk, MatchesClippingEveryPlaneAndSphereTracing) {
  Rng rng(2024);
  std::vector<Shape> hulls;
  hulls.push_back(Shape::convex(testing::random_hull_points(rng, 250, 0.4, 1.2)));
  hulls.push_back(Shape::convex(testing::random_hull_points(rng, 60, 0.5, 0.5)));
  std::vector<Eigen::Vector3d> cube;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j)
      for (int k = 0; k <= 4; ++k)
        if (i % 4 == 0 || j % 4 == 0 || k % 4 == 0) cube.push_back(Eigen::Vector3d(i, j, k) / 4.0 - Eigen::Vector3d(0.5, 0.5, 0.5));
  hulls.push_back(Shape::convex(cube));
  for (const Shape& hull : hulls) {
    kr::HullPlanes<double> planes = kr::make_hull_planes<double>(hull_view(*hull.hull));
    // Also below kHullWalkMinFaces (the cube has 12 faces).
    planes.walk = kr::make_hull_walk<double>(hull_view(*hull.hull));
    int hits = 0;
    for (const Ray& r : random_rays(rng, 3000, 1.0)) {
      bool ok = false;
      const kr::LocalHit<double> walk = kr::ray_hull_walk(planes.walk, r.o, r.d, r.t_max, ok);
      ASSERT_TRUE(ok);
      const kr::LocalHit<double> clip = kr::finish(kr::ray_convex(r.o, r.d, planes), r.d, r.t_max);
      ASSERT_EQ(walk.hit, clip.hit) << r.o.transpose() << " / " << r.d.transpose();
      if (!walk.hit) continue;
      ++hits;
      EXPECT_NEAR(walk.t, clip.t, 1e-12 * (1 + clip.t));
      if (walk.t > 0) { EXPECT_GT(walk.normal.dot(clip.normal), 1 - 1e-9); }  // the same facet (or two that tie)
    }
    EXPECT_GT(hits, 500);
    EXPECT_GE(check_shape(hull, 1500, 7).compared, 1450);
  }
  // qhull keeps the cube's 8 corners and triangulates each square: 12 triangles, merged into 6 facets. The large hull
  // takes the walk in ray_local.
  EXPECT_EQ(hulls[2].hull->faces.size(), 12u);
  EXPECT_EQ(kr::make_hull_walk<double>(hull_view(*hulls[2].hull)).planes(), 6u);
  EXPECT_GT(kr::make_hull_planes<double>(hull_view(*hulls[0].hull)).walk.planes(), 0u);
}

}  // namespace
}  // namespace batchcol

namespace batchcol {
namespace {

// The walk may start at any parameter outside the hull (ray_local passes the bounding ball's entry, moved back by
// hull_walk_start()): the answer is the one of the walk from the origin, bit for bit, since t comes from the entry
// facet's plane and the ray only. A start inside the hull restarts from the origin, also with the same answer.
TEST(RayHullWalk, StartingAtTheBallEntryGivesTheSameBits) {
  Rng rng(77);
  const Shape hull = Shape::convex(testing::random_hull_points(rng, 250, 0.5, 0.5));
  const kr::HullPlanes<double> planes = kr::make_hull_planes<double>(hull_view(*hull.hull));
  ASSERT_GT(planes.walk.planes(), 0u);
  const double bound = hull.bounding_radius() * (1 + 64 * kernels::machine_epsilon<double>());
  int from_ball = 0, restarted = 0, hits = 0;
  for (const Ray& r : random_rays(rng, 3000, 1.0)) {
    bool ok0 = false, ok1 = false;
    const kr::LocalHit<double> h0 = kr::ray_hull_walk(planes.walk, r.o, r.d, r.t_max, ok0);
    const kr::RayInterval<double> ball = kr::ray_sphere(r.o, r.d, bound);
    if (ball.empty() || ball.exit < 0 || ball.enter > r.t_max) {
      EXPECT_FALSE(h0.hit);
      continue;
    }
    const double start = kr::hull_walk_start(ball.enter, r.o, r.d, hull.bounding_radius());
    const kr::LocalHit<double> h1 = kr::ray_hull_walk(planes.walk, r.o, r.d, r.t_max, ok1, start);
    ASSERT_TRUE(ok0 && ok1);
    from_ball += start > 0;
    ASSERT_EQ(h0.hit, h1.hit) << r.o.transpose() << " / " << r.d.transpose();
    if (!h0.hit) continue;
    ++hits;
    EXPECT_EQ(h0.t, h1.t);
    EXPECT_EQ(h0.normal, h1.normal);
    // Halfway from the origin to the entry (outside), and halfway through the hull (inside: a restart).
    const double exit = std::min(r.t_max, kr::ray_convex(r.o, r.d, planes).exit);
    if (h0.t > 0 && exit - h0.t > 1e-6) {
      for (const double mid : {0.5 * h0.t, 0.5 * (h0.t + exit)}) {
        bool ok2 = false;
        const kr::LocalHit<double> h2 = kr::ray_hull_walk(planes.walk, r.o, r.d, r.t_max, ok2, mid);
        ASSERT_TRUE(ok2 && h2.hit);
        EXPECT_EQ(h2.t, h0.t);
        EXPECT_EQ(h2.normal, h0.normal);
        ++restarted;
      }
    }
  }
  EXPECT_GT(from_ball, 400);  // origins in a 6 m cube: some start inside the ball
  EXPECT_GT(hits, 500);
  EXPECT_GT(restarted, 500);
}

}  // namespace
}  // namespace batchcol
