// Hard cases, scale: needles and plates (aspect 1e4), size ratios 1e6, coordinates 1e4 and 1e6 m from the origin,
// identical poses, ellipsoids with radii ratio 1e3; double and float through the public batchcol::collide().
// Expected distances are closed forms (extents along the separating axis, or the shape's minimal width for
// identical poses). Each test prints the measured maximum error ("[measured]" lines) next to its bound.
#include "support/hard_cases.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using testing::beside;
using testing::expect_sane;
using testing::hard_case_options;
using testing::kEpsFloat;
using testing::kIdentity;
using testing::precision_name;

const Eigen::Quaterniond kAlongX(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));  // local z -> world -x/+x
const Eigen::Quaterniond kAlongY(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));  // local z -> world -y

TEST(HardCasesScale, NeedlesAndPlatesAspectRatio1e4) {
  const Shape needle = Shape::capsule(1e-5, 0.1);  // 2e-5 thick, 0.2 long
  const Shape rod = Shape::cylinder(1e-5, 0.1);
  const Shape plate = Shape::box(2e-5, 0.2, 0.2);  // its thin axis is x, the separating axis
  for (Precision p : {Precision::float64, Precision::float32}) {
    // Double: exact to rounding (measured 3e-16 m), bound 1e-13. Float: measured 1e-6 m (a 1e-6 gap reported as
    // touching), bound 16 eps_f * 1 m.
    const double bound = p == Precision::float64 ? 1e-13 : 16 * kEpsFloat;
    double worst = 0.0;
    struct Case { const char* name; Shape a; Eigen::Quaterniond ra; Shape b; Eigen::Quaterniond rb; Eigen::Vector3d lateral; };
    const std::vector<Case> cases = {
        {"needle flat on plate", plate, kIdentity, needle, kAlongY, {0, 0.01, 0.05}},
        {"rod flat on plate", plate, kIdentity, rod, kAlongY, {0, -0.02, 0.03}},
        {"needle tip on plate", plate, kIdentity, needle, kAlongX, {0, 0.05, -0.07}},
        {"plate on plate", plate, kIdentity, plate, kIdentity, {0, 0.1, 0.05}},
        {"crossed needles", needle, kAlongY, needle, kIdentity, Eigen::Vector3d::Zero()},
        {"plate edge on plate", plate, kIdentity, plate, Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())), {0, 0.05, 0}},
    };
    for (const auto& c : cases)
      for (double gap : {1e-3, 1e-6, 1e-9, -1e-6, -1e-9}) {
        SCOPED_TRACE(std::string(c.name) + " gap " + std::to_string(gap) + " " + precision_name(p));
        const auto r = beside(c.a, c.ra, c.b, c.rb, gap, Eigen::Vector3d(0.1, 0.2, -0.3), kIdentity, hard_case_options(p), c.lateral);
        // In float a +-1e-9 contact of the 1e-5 m rod is below the floor: EPA may report its flat Minkowski
        // difference as `degenerate` (measured: rod flat on plate); the distance is still within the bound.
        if (p == Precision::float32 && std::abs(gap) < bound && r.status == Status::degenerate) {
          EXPECT_LE(std::abs(r.distance - gap), bound);
          continue;
        }
        expect_sane(r, QueryLevel::penetration, 4 * bound);
        EXPECT_LE(std::abs(r.distance - gap), bound);
        worst = std::max(worst, std::abs(r.distance - gap));
      }
    std::printf("[measured] needles and plates (aspect 1e4), %s: max |error| %.3g m (bound %.2g)\n", precision_name(p), worst, bound);
  }
}

TEST(HardCasesScale, SizeRatio1e6) {
  // A 100 m box or ball against 1e-4 m shapes. The error scales with the large shape (the precision floor is
  // 16 eps (radii + centre distance)): double measured 8.1e-15 m, bound 1e-12; float measured 2.3e-5 m, bound
  // 16 eps_f * 200 m (smaller gaps may be reported as touching).
  const Shape big_box = Shape::box(100, 100, 100), big_ball = Shape::sphere(100);
  const std::vector<Shape> tiny = {Shape::sphere(1e-4), Shape::box(1e-4, 1e-4, 1e-4), Shape::cylinder(1e-4, 1e-4),
                                   Shape::ellipsoid(1e-4, 5e-5, 1e-4)};
  for (Precision p : {Precision::float64, Precision::float32}) {
    const double bound = p == Precision::float64 ? 1e-12 : 16 * kEpsFloat * 200;
    double worst = 0.0;
    for (const Shape& big : {big_box, big_ball})
      for (const Shape& small : tiny)
        for (double gap : {1e-3, 1e-6, 1e-9}) {
          SCOPED_TRACE(std::string(to_string(big.type)) + "-" + to_string(small.type) + " gap " + std::to_string(gap) + " " + precision_name(p));
          const Eigen::Vector3d lateral = big.type == ShapeType::box ? Eigen::Vector3d(0, 3, -7) : Eigen::Vector3d::Zero();
          const auto r = beside(big, kIdentity, small, kIdentity, gap, Eigen::Vector3d::Zero(), kIdentity,
                                hard_case_options(p, QueryLevel::witness), lateral);
          // Gaps below the precision floor may be decided as touching (collide, no distance at this level).
          expect_sane(r, QueryLevel::witness, 4 * bound, 1e3);
          if (r.collide) {
            EXPECT_LE(gap, bound);
            continue;
          }
          EXPECT_LE(std::abs(r.distance - gap), bound);
          worst = std::max(worst, std::abs(r.distance - gap));
        }
    std::printf("[measured] size ratio 1e6, %s: max |error| %.3g m (bound %.2g)\n", precision_name(p), worst, bound);
  }
}

TEST(HardCasesScale, CoordinatesFarFromTheOrigin) {
  // Poses at 1e4 and 1e6 m under a common rotation. Double: the world coordinates round to ulp(1e6) = 1.2e-10 m
  // before the relative pose is formed; measured 6.6e-11 m at 1e6 (8.5e-13 at 1e4), bound 1e-9 (1e-11). Float runs
  // on the relative pose (computed in double), so its error does not grow with the distance to the origin: measured
  // 1e-6 m at both, bound 16 eps_f * 1 m.
  testing::Rng rng(21);
  struct Case {
    const char* name;
    Shape a;
    Eigen::Quaterniond ra;
    Shape b;
    Eigen::Quaterniond rb;
    bool overlaps;
    Eigen::Vector3d lateral;
  };
  const std::vector<Case> cases = {
      {"box-box", Shape::box(0.1, 0.2, 0.3), kIdentity, Shape::box(0.2, 0.1, 0.1), kIdentity, true, {0, 0.05, 0}},
      {"box-ellipsoid", Shape::box(0.3, 0.3, 0.3), kIdentity, Shape::ellipsoid(0.1, 0.05, 0.2), kIdentity, true, {0, 0, 0.1}},
      {"cylinder-capsule", Shape::cylinder(0.1, 0.2), kIdentity, Shape::capsule(0.05, 0.2), kAlongY, false, Eigen::Vector3d::Zero()},
      // The cone's -x extreme is its base rim at local z = -0.2: lift the cone so the rim faces the ball's +x pole.
      {"sphere-cone", Shape::sphere(0.1), kIdentity, Shape::cone(0.1, 0.2), kIdentity, false, {0, 0, 0.2}},
  };
  for (Precision p : {Precision::float64, Precision::float32})
    for (double far : {1e4, 1e6}) {
      const double bound = p == Precision::float64 ? (far > 1e5 ? 1e-9 : 1e-11) : 16 * kEpsFloat * 1.0;
      double worst = 0.0;
      for (int trial = 0; trial < 8; ++trial) {
        const Eigen::Quaterniond Q = testing::random_rotation(rng);
        const Eigen::Vector3d T = far * testing::random_unit_vector(rng);
        for (const auto& c : cases)
          for (double gap : {1e-2, 1e-4, 1e-6, -1e-4, -1e-6}) {
            if (gap < 0 && !c.overlaps) continue;
            SCOPED_TRACE(std::string(c.name) + " at " + std::to_string(far) + " gap " + std::to_string(gap) + " " + precision_name(p));
            const auto r = beside(c.a, c.ra, c.b, c.rb, gap, T, Q, hard_case_options(p), c.lateral);
            // The witness points are world coordinates ~1e6 m: their identity holds to their own rounding.
            expect_sane(r, QueryLevel::penetration, 4 * bound + 8 * far * std::numeric_limits<double>::epsilon());
            EXPECT_LE(std::abs(r.distance - gap), bound);
            worst = std::max(worst, std::abs(r.distance - gap));
          }
      }
      std::printf("[measured] %.0e m from the origin, %s: max |error| %.3g m (bound %.2g)\n", far, precision_name(p), worst, bound);
    }
}

TEST(HardCasesScale, IdenticalPosesGiveTheMinimalWidth) {
  // Two copies of a shape at one pose: the depth is the shape's minimal width min_u (h(u) + h(-u)).
  testing::Rng rng(4);
  struct Case { Shape shape; double width; };
  const std::vector<Case> cases = {
      {Shape::sphere(0.13), 0.26},
      {Shape::box(0.1, 0.05, 0.3), 0.1},
      {Shape::ellipsoid(0.2, 0.07, 0.1), 0.14},
      {Shape::capsule(0.04, 0.2), 0.08},
      {Shape::cylinder(0.1, 0.03), 0.06},
      {Shape::box(0.1, 0.1, 0.1).inflated(0.02), 0.24},
  };
  for (Precision p : {Precision::float64, Precision::float32}) {
    // Double (EPA tolerance 1e-9): measured 2.6e-10 m, bound 1e-9. Float: measured 2.5e-7 m, bound 40 eps_f * 1 m.
    const double bound = p == Precision::float64 ? 1e-9 : 40 * kEpsFloat;
    double worst = 0.0;
    for (const auto& c : cases)
      for (int trial = 0; trial < 4; ++trial) {
        const Pose pose{testing::random_vector(rng), testing::random_rotation(rng)};
        SCOPED_TRACE(std::string(to_string(c.shape.type)) + " trial " + std::to_string(trial) + " " + precision_name(p));
        QueryOptions o = hard_case_options(p);
        if (p == Precision::float64) o.tolerance = 1e-9;  // EPA on a curved Minkowski difference: 1e-12 needs >2000 faces
        const auto r = testing::run_pair(c.shape, pose, c.shape, pose, o);
        expect_sane(r, QueryLevel::penetration, 4 * bound);
        EXPECT_TRUE(r.collide);
        EXPECT_LE(std::abs(r.distance + c.width), bound);
        worst = std::max(worst, std::abs(r.distance + c.width));
      }
    // Shapes without a simple width formula: only sanity (finite, overlapping, negative distance).
    for (ShapeType t : {ShapeType::cone, ShapeType::convex}) {
      const Shape s = testing::random_shape(rng, t);
      const Pose pose{testing::random_vector(rng), testing::random_rotation(rng)};
      const auto r = testing::run_pair(s, pose, s, pose, hard_case_options(p));
      SCOPED_TRACE(std::string(to_string(t)) + " " + precision_name(p));
      // A cone's self Minkowski difference is curved around its minimal width too: EPA may run out of budget
      // (measured: max_iterations on cones), the result stays finite and overlapping.
      EXPECT_TRUE(r.status == Status::converged || r.status == Status::max_iterations) << to_string(r.status);
      ASSERT_TRUE(std::isfinite(r.distance) && r.normal.allFinite() && r.witness_a.allFinite() && r.witness_b.allFinite());
      EXPECT_TRUE(r.collide);
      EXPECT_LT(r.distance, 0.0);
    }
    // A long cylinder's smallest width is radial: a whole circle of minimal directions, which EPA's lower bound
    // approximates face by face (1.9e-6 m off after 1000 expansions, 2e-8 after 10000). In double at tolerance
    // 1e-12 the budget runs out (honest status max_iterations) and EPA returns its best upper bound, which any
    // radial support attains exactly: measured 2.8e-17 m. Float's tolerance is its floor 16 eps_f x 0.61 m, which
    // EPA reaches: converged, measured 7.5e-7 m; bound 20 eps_f x 1 m.
    const double rod_bound = p == Precision::float64 ? 1e-12 : 20 * kEpsFloat;
    double rod_worst = 0.0;
    for (int trial = 0; trial < 4; ++trial) {
      const Shape rod = Shape::cylinder(0.05, 0.3);
      const Pose pose{testing::random_vector(rng), testing::random_rotation(rng)};
      const auto r = testing::run_pair(rod, pose, rod, pose, hard_case_options(p));
      SCOPED_TRACE("long cylinder trial " + std::to_string(trial) + " " + precision_name(p));
      EXPECT_EQ(r.status, p == Precision::float64 ? Status::max_iterations : Status::converged);
      ASSERT_TRUE(std::isfinite(r.distance) && r.normal.allFinite());
      EXPECT_LE(std::abs(r.distance + 0.1), rod_bound);
      rod_worst = std::max(rod_worst, std::abs(r.distance + 0.1));
      EXPECT_LT(std::abs(r.normal.dot(pose.rotation * Eigen::Vector3d::UnitZ())), 1e-3);  // radial
    }
    std::printf("[measured] identical long cylinders, %s: max |depth error| %.3g m (bound %.2g)\n", precision_name(p),
                rod_worst, rod_bound);
    std::printf("[measured] identical poses, %s: max |depth error| %.3g m (bound %.2g)\n", precision_name(p), worst, bound);
  }
}

TEST(HardCasesScale, EllipsoidsWithRadiiRatio1e3) {
  const Shape wall = Shape::box(0.5, 0.5, 0.5);
  const Shape needle_y = Shape::ellipsoid(2e-4, 0.2, 2e-4), needle_z = Shape::ellipsoid(2e-4, 2e-4, 0.2);
  const Shape pancake = Shape::ellipsoid(2e-4, 0.2, 0.2);  // thin along x
  testing::Rng rng(8);
  for (Precision p : {Precision::float64, Precision::float32}) {
    // Double: measured 1.1e-13 m, bound 1e-10. Float: measured 1.3e-6 m, bound 16 eps_f * 1 m.
    const double bound = p == Precision::float64 ? 1e-10 : 16 * kEpsFloat;
    double worst = 0.0;
    const auto check = [&](const testing::SingleResult& r, double gap, const std::string& what) {
      SCOPED_TRACE(what + " gap " + std::to_string(gap) + " " + precision_name(p));
      expect_sane(r, QueryLevel::penetration, 4 * bound);
      EXPECT_LE(std::abs(r.distance - gap), bound);
      worst = std::max(worst, std::abs(r.distance - gap));
    };
    for (double gap : {1e-3, 1e-6, 1e-9}) {
      check(beside(needle_y, kIdentity, needle_z, kIdentity, gap, Eigen::Vector3d(0.1, 0, 0), kIdentity, hard_case_options(p)),
            gap, "crossed needles");
      // Centred on one axis: with a lateral offset the curved faces would be further apart than the gap.
      check(beside(pancake, kIdentity, pancake, kIdentity, gap, Eigen::Vector3d(0.1, 0, 0), kIdentity, hard_case_options(p)),
            gap, "stacked pancakes");
    }
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Quaterniond R = testing::random_rotation(rng);
      const Shape& e = trial % 2 ? pancake : needle_z;
      for (double gap : {1e-3, 1e-6, 1e-9, -1e-6, -1e-9})  // tip into a wall face: the depth is the overlap too
        check(beside(wall, kIdentity, e, R, gap, Eigen::Vector3d::Zero(), kIdentity, hard_case_options(p)), gap,
              "rotated ellipsoid on a wall, trial " + std::to_string(trial));
    }
    std::printf("[measured] ellipsoids radii ratio 1e3, %s: max |error| %.3g m (bound %.2g)\n", precision_name(p), worst, bound);
  }
}

}  // namespace
}  // namespace batchcol
