// Penetration depths that ended without convergence (issue #16, item 10): sphere-cylinder (and sphere-cone)
// overlaps under every solver (one ended `degenerate` under nesterov and polyak), and sphere-like ellipsoids at an
// identical pose (`max_iterations`). References in closed form:
//  - sphere (centre c, radius r) and cylinder/cone: r + the distance from c to the boundary when c is inside the
//    core, else r - the distance from c to the core (2D, in the half-plane of c through the axis);
//  - two ellipsoids with the same centre and axes, radii a and b: min_i (a_i + b_i). The depth is
//    min over unit n of |a .* n| + |b .* n|; as a function of (n_x^2, n_y^2, n_z^2) on the simplex each term is
//    the square root of a linear function (concave), so the minimum is at a vertex: an axis.
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace batchcol {
namespace {

/// Signed distance from a local point to a cylinder or cone (negative inside), in the point's half-plane.
double signed_distance(bool cone, double R, double h, const Eigen::Vector3d& p) {
  const Eigen::Vector2d q(std::hypot(p.x(), p.y()), p.z());
  // The profile polygon in the (rho, z) half-plane: (0, -h), (R, -h), (R, h), (0, h); a cone's ends at its apex.
  const Eigen::Vector2d v[4] = {{0, -h}, {R, -h}, {cone ? 0.0 : R, h}, {0, h}};
  double outside = HUGE_VAL;
  bool inside = true;
  for (int i = 0; i < (cone ? 2 : 3); ++i) {  // the edge on the axis is not part of the boundary
    const Eigen::Vector2d a = v[i], b = v[i + 1], e = b - a;
    const double t = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    outside = std::min(outside, (a + t * e - q).norm());
    if (e.x() * (q.y() - a.y()) - e.y() * (q.x() - a.x()) < 0) inside = false;  // right of the edge: outside
  }
  return inside ? -outside : outside;
}

QueryOptions depth_options(Solver solver, Precision precision, double tolerance) {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.solver = solver;
  o.precision = precision;
  o.tolerance = tolerance;
  return o;
}

TEST(PenetrationConvergence, SphereCylinderAndConeOverlapsConvergeUnderEverySolver) {
  testing::Rng rng(1610);
  double worst[2] = {0, 0}, worst_m[2] = {0, 0};
  int pairs = 0;
  for (bool cone : {false, true})
    for (int i = 0; i < 400; ++i) {
      const double R = testing::uniform(rng, 0.05, 1.0), h = testing::uniform(rng, 0.05, 1.0);
      const double r = testing::uniform(rng, 0.01, 0.5);
      // A centre within r of the core (inside or outside it): uniform by rejection, or (every other pair) within
      // 1e-12..1e-3 of the core's boundary (side, cap, rim or apex), where the cores barely touch or overlap.
      Eigen::Vector3d c;
      double sd;
      do {
        if (i % 2 == 0) {
          c = Eigen::Vector3d(testing::uniform(rng, -R - r, R + r), testing::uniform(rng, -R - r, R + r),
                              testing::uniform(rng, -h - r, h + r));
        } else {
          const double phi = testing::uniform(rng, 0, 2 * M_PI), z = testing::uniform(rng, -h, h);
          const Eigen::Vector3d radial(std::cos(phi), std::sin(phi), 0);
          Eigen::Vector3d x, n;
          switch (static_cast<int>(testing::uniform(rng, 0, 4))) {
            case 0:  // side
              x = (cone ? R * (h - z) / (2 * h) : R) * radial + Eigen::Vector3d(0, 0, z);
              n = cone ? Eigen::Vector3d(2 * h * radial + R * Eigen::Vector3d::UnitZ()).normalized() : radial;
              break;
            case 1:  // bottom cap (top for a cylinder, half of the time)
              x = testing::uniform(rng, 0, R) * radial + Eigen::Vector3d(0, 0, -h);
              n = -Eigen::Vector3d::UnitZ();
              if (!cone && z > 0) x.z() = h, n = Eigen::Vector3d::UnitZ();
              break;
            case 2:  // bottom rim
              x = R * radial + Eigen::Vector3d(0, 0, -h);
              n = (radial - Eigen::Vector3d::UnitZ()).normalized();
              break;
            default:  // apex or top rim
              x = cone ? Eigen::Vector3d(0, 0, h) : Eigen::Vector3d(R * radial + Eigen::Vector3d(0, 0, h));
              n = cone ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(radial + Eigen::Vector3d::UnitZ()).normalized();
          }
          c = x + (z > 0 ? 1 : -1) * std::pow(10.0, -testing::uniform(rng, 3, 12)) * n;
        }
        sd = signed_distance(cone, R, h, c);
      } while (!(sd < r - 1e-6));
      const double depth = r - sd;
      const Pose body{Eigen::Vector3d(0.3, -0.2, 0.1), testing::random_rotation(rng)};
      const Pose ball{body.translation + body.rotation * c, testing::random_rotation(rng)};
      const Shape a = cone ? Shape::cone(R, h) : Shape::cylinder(R, h), b = Shape::sphere(r);
      for (Solver solver : {Solver::nesterov, Solver::polyak, Solver::gjk})
        for (Precision precision : {Precision::float64, Precision::float32})
          for (double tolerance : {1e-6, 1e-8, 1e-12}) {
            SCOPED_TRACE(std::string(cone ? "cone " : "cylinder ") + to_string(solver) + " " + to_string(precision) +
                         " tolerance " + std::to_string(tolerance) + " pair " + std::to_string(i));
            const bool single = precision == Precision::float32;
            const auto o = depth_options(solver, precision, tolerance);
            for (bool swap : {false, true}) {
              const auto res = swap ? testing::run_pair(b, ball, a, body, o) : testing::run_pair(a, body, b, ball, o);
              ++pairs;
              ASSERT_EQ(res.status, Status::converged) << "centre " << sd << " m from the core's boundary";
              EXPECT_TRUE(res.collide);
              // The tolerance, at least the precision floor (16 eps x ~2 m: 4e-6 m in float). Double: GJK stalls
              // accepted at the arithmetic's limit (complete_from_gjk) leave up to ~1e-11 m on centres ~1e-12 m
              // outside the core (measured 9.2e-12 m at tolerance 1e-12).
              const double bound = std::max(tolerance, single ? 4e-6 : 1e-11);
              EXPECT_NEAR(res.distance, -depth, bound);
              worst[single] = std::max(worst[single], std::abs(res.distance + depth) / bound);
              worst_m[single] = std::max(worst_m[single], std::abs(res.distance + depth));
            }
          }
    }
  std::printf("[measured] %d sphere-cylinder/cone overlaps (3 solvers, 3 tolerances): worst |depth error| / "
              "bound: double %.3g (%.3g m), float %.3g (%.3g m)\n",
              pairs, worst[0], worst_m[0], worst[1], worst_m[1]);
}

TEST(PenetrationConvergence, SphereLikeEllipsoidsAtTheSamePoseConverge) {
  testing::Rng rng(1611);
  double worst = 0;
  for (int i = 0; i < 120; ++i) {
    // Radii within 1e-7 relative of each other (the 0.5, 0.5, 0.5000001 first), then a random spread.
    Eigen::Vector3d a(0.5, 0.5, 0.5000001), b = a;
    if (i > 0) {
      const double base = testing::uniform(rng, 0.01, 1.0), spread = std::pow(10.0, testing::uniform(rng, -9, -1));
      for (int k = 0; k < 3; ++k) {
        a[k] = base * (1 + spread * testing::uniform(rng, 0, 1));
        b[k] = base * (1 + spread * testing::uniform(rng, 0, 1));
      }
    }
    const double depth = (a + b).minCoeff();
    const Pose pose{Eigen::Vector3d(testing::uniform(rng, -1, 1), 0.2, -0.4), testing::random_rotation(rng)};
    for (Precision precision : {Precision::float64, Precision::float32})
      for (Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak})
        for (double tolerance : {1e-6, 1e-9, 1e-12}) {
          SCOPED_TRACE("ellipsoids " + std::to_string(i) + " " + to_string(precision) + " " + to_string(solver) +
                       " tolerance " + std::to_string(tolerance));
          const bool single = precision == Precision::float32;
          const auto res = testing::run_pair(Shape::ellipsoid(a.x(), a.y(), a.z()), pose,
                                             Shape::ellipsoid(b.x(), b.y(), b.z()), pose,
                                             depth_options(solver, precision, tolerance));
          ASSERT_EQ(res.status, Status::converged);
          const double bound = std::max(tolerance, single ? 2e-6 : 1e-14) + (single ? 0 : 1e-15);
          EXPECT_NEAR(res.distance, -depth, bound);
          worst = std::max(worst, std::abs(res.distance + depth) / std::max(tolerance, single ? 2e-6 : 0.0));
          EXPECT_NEAR(res.normal.norm(), 1.0, 1e-6);
        }
  }
  std::printf("[measured] sphere-like ellipsoids at one pose: worst |depth error| / max(tolerance, floor) %.3g\n",
              worst);
}

}  // namespace
}  // namespace batchcol
