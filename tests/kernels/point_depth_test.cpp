// Penetration depth of a sphere centred inside a cylinder or cone (issue #16, item 10): EPA ended max_iterations at
// every tolerance with errors of ~1e-5 x the size; the closed form (kernels/point_depth.hpp) must be converged and
// exact to rounding. The reference here is computed differently: the distance from the centre to the boundary as
// the smallest distance to the caps (planes) and to the side, the side distance found by projecting the point on
// the side's generating segment in the point's own half-plane (vector projection, clamped), not by the implicit
// normal of the implementation.
#include <batchcol/batchcol.hpp>

#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace batchcol {
namespace {

// Distance from p (local frame) to the boundary of a cylinder (cone = false) or cone of radius R, half length h.
double reference_depth(bool cone, double R, double h, const Eigen::Vector3d& p) {
  const double rho = std::hypot(p.x(), p.y());
  double best = std::min(h + p.z(), cone ? HUGE_VAL : h - p.z());
  // The side's generating segment in the (rho, z) half-plane of p.
  const Eigen::Vector2d a = cone ? Eigen::Vector2d(0, h) : Eigen::Vector2d(R, h), b(R, -h), q(rho, p.z());
  const double t = std::clamp((q - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  best = std::min(best, (a + t * (b - a) - q).norm());
  return best;
}

TEST(PointDepth, SphereCentredInsideCylinderOrConeIsExact) {
  testing::Rng rng(10);
  double worst[2] = {0, 0};
  for (bool cone : {false, true})
    for (Precision precision : {Precision::float64, Precision::float32})
      for (int i = 0; i < 300; ++i) {
        const double R = testing::uniform(rng, 0.1, 1.0), h = testing::uniform(rng, 0.1, 1.0);
        const double r = testing::uniform(rng, 0.01, 0.5);
        // A point strictly inside: rho and z drawn inside the profile, kept 1e-3 away from the boundary.
        const double z = testing::uniform(rng, -h + 1e-3, h - 1e-3);
        const double max_rho = (cone ? R * (h - z) / (2 * h) : R) - 1e-3;
        if (max_rho <= 0) continue;
        const double rho = testing::uniform(rng, 0.0, max_rho), phi = testing::uniform(rng, 0.0, 2 * M_PI);
        const Eigen::Vector3d local(rho * std::cos(phi), rho * std::sin(phi), z);
        const double depth = reference_depth(cone, R, h, local) + r;
        ShapeTable shapes;
        shapes.add(cone ? Shape::cone(R, h) : Shape::cylinder(R, h));
        shapes.add(Shape::sphere(r));
        const Pose body{Eigen::Vector3d(0.3, -0.2, 0.1), testing::random_rotation(rng)};
        const Pose ball{body.translation + body.rotation * local, testing::random_rotation(rng)};
        PairBatch batch;
        batch.add(0, body, 1, ball);
        batch.add(1, ball, 0, body);
        QueryOptions o;
        o.level = QueryLevel::penetration;
        o.precision = precision;
        o.tolerance = 1e-12;
        PairResults out;
        collide(shapes, batch, o, out);
        const double bound = precision == Precision::float64 ? 1e-13 : 2e-6;
        for (std::size_t k = 0; k < 2; ++k) {
          SCOPED_TRACE(std::string(cone ? "cone" : "cylinder") + (k ? " sphere first" : " sphere second") + " " +
                       to_string(precision) + " pair " + std::to_string(i));
          EXPECT_EQ(out.status[k], Status::converged);
          EXPECT_EQ(out.collide[k], 1);
          EXPECT_NEAR(out.distance[k], -depth, bound);
          worst[precision == Precision::float32] = std::max(worst[precision == Precision::float32],
                                                            std::abs(out.distance[k] + depth));
          const Eigen::Vector3d gap = out.witness_b[k] - out.witness_a[k];
          EXPECT_LE((gap - out.distance[k] * out.normal[k]).norm(), 10 * bound);
          EXPECT_NEAR(out.normal[k].norm(), 1.0, 10 * bound);
        }
      }
  std::printf("[measured] sphere inside cylinder/cone, depth error: double %.3g m, float %.3g m\n", worst[0], worst[1]);
}

}  // namespace
}  // namespace batchcol
