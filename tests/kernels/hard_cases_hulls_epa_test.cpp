// Hard cases: hulls built from messy points (duplicates, points on faces, nearly coplanar points) compared with the
// same polytope given independently as a box primitive; and EPA on curved shapes (sphere, capsule, ellipsoid,
// cylinder, cone), shallow and deep, against closed-form depths. Double and float through batchcol::collide().
// Each test prints the measured maximum error ("[measured]" lines) next to its bound.
#include "support/hard_cases.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using testing::expect_sane;
using testing::hard_case_options;
using testing::kEpsFloat;
using testing::kIdentity;
using testing::precision_name;

std::vector<Eigen::Vector3d> box_corners(const Eigen::Vector3d& h) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 8; ++i) out.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
  return out;
}

/// The corners of the box h, plus: every corner twice more, a 7 x 7 grid on each face (coplanar points), edge
/// midpoints, interior points, and face points moved inwards by `inward` (nearly coplanar).
std::vector<Eigen::Vector3d> messy_box_points(const Eigen::Vector3d& h, double inward, testing::Rng& rng) {
  std::vector<Eigen::Vector3d> out = box_corners(h);
  const auto corners = box_corners(h);
  out.insert(out.end(), corners.begin(), corners.end());
  out.insert(out.end(), corners.begin(), corners.end());
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0})
      for (int i = 0; i <= 6; ++i)
        for (int j = 0; j <= 6; ++j) {
          Eigen::Vector3d p;
          p[axis] = side * h[axis];
          p[(axis + 1) % 3] = h[(axis + 1) % 3] * (i / 3.0 - 1.0);
          p[(axis + 2) % 3] = h[(axis + 2) % 3] * (j / 3.0 - 1.0);
          out.push_back(p);
          if (inward > 0.0 && i % 2 && j % 2) {
            p[axis] -= side * inward;
            out.push_back(p);
          }
        }
  for (int k = 0; k < 20; ++k)
    out.push_back(h.cwiseProduct(Eigen::Vector3d(testing::uniform(rng, -1, 1), testing::uniform(rng, -1, 1),
                                                 testing::uniform(rng, -1, 1))));
  return out;
}

TEST(HardCasesHulls, MessyPointsGiveTheSamePolytopeAsTheBoxPrimitive) {
  // The hull of messy points on a box is that box: compare hull-X with box-X on the same poses, X every primitive.
  testing::Rng rng(31);
  const Eigen::Vector3d h(0.1, 0.15, 0.05);
  for (double inward : {0.0, 1e-13, 1e-9}) {
    const Shape hull = Shape::convex(messy_box_points(h, inward, rng));
    EXPECT_EQ(hull.hull->vertices.size(), 8u) << "inward " << inward;
  }
  const Shape hull = Shape::convex(messy_box_points(h, 1e-13, rng));
  const Shape box = Shape::box(h);
  for (Precision p : {Precision::float64, Precision::float32}) {
    // Double: polytope partners exact to rounding (bound 1e-12), curved partners within 2 x tolerance (measured
    // 2.1e-11 m, bound 2e-10). Float: each is within its floor of the truth; measured 1.2e-7 m apart, bound
    // 16 eps_f * 1 m.
    const double bound = p == Precision::float64 ? 1e-12 : 16 * kEpsFloat;
    double worst = 0.0;
    for (ShapeType t : testing::bounded_shape_types())
      for (int trial = 0; trial < 30; ++trial) {
        const Shape other = testing::random_shape(rng, t);
        const Pose pa{testing::random_vector(rng) * 0.1, testing::random_rotation(rng)};
        const Pose pb{testing::random_vector(rng) * 0.4, testing::random_rotation(rng)};
        SCOPED_TRACE(std::string(to_string(t)) + " trial " + std::to_string(trial) + " " + precision_name(p));
        const auto from_hull = testing::run_pair(hull, pa, other, pb, hard_case_options(p, QueryLevel::penetration, 1e-10));
        const auto from_box = testing::run_pair(box, pa, other, pb, hard_case_options(p, QueryLevel::penetration, 1e-10));
        expect_sane(from_hull, QueryLevel::penetration, 1e-6);
        EXPECT_EQ(from_hull.collide, from_box.collide);
        // Both are certified to the tolerance 1e-10 (curved partners) or exact (polytopes): 2 x 1e-10 apart at most.
        const double allowed = p == Precision::float64 ? (t == ShapeType::box || t == ShapeType::convex ? bound : 2e-10) : bound;
        EXPECT_LE(std::abs(from_hull.distance - from_box.distance), allowed);
        worst = std::max(worst, std::abs(from_hull.distance - from_box.distance));
      }
    std::printf("[measured] messy hull vs box primitive, %s: max |difference| %.3g m\n", precision_name(p), worst);
  }
}

TEST(HardCasesHulls, NearlyCoplanarSliverAndNeedleHulls) {
  // A tetrahedron of height 1e-7 over a 0.1 m triangle (aspect 1e6) and one with a 1e-9 m bump: valid hulls whose
  // distances to a ball above them are closed forms (the ball's centre projects inside the top vertex's region).
  for (double height : {1e-5, 1e-7, 1e-9}) {
    const Shape sliver = Shape::convex({{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0.03, 0.03, height}});
    EXPECT_EQ(sliver.hull->vertices.size(), 4u);
    for (Precision p : {Precision::float64, Precision::float32}) {
      // Double: exact to rounding, bound 1e-12; float: bound 16 eps_f * 0.1 m (the problem's scale).
      const double bound = p == Precision::float64 ? 1e-12 : 16 * kEpsFloat * 0.1;
      SCOPED_TRACE("height " + std::to_string(height) + " " + precision_name(p));
      const auto r = testing::run_pair(sliver, Pose{}, Shape::sphere(0.01), Pose::from_translation({0.03, 0.03, 0.02}),
                                       hard_case_options(p));
      expect_sane(r, QueryLevel::penetration, 4 * bound);
      EXPECT_LE(std::abs(r.distance - (0.02 - height - 0.01)), bound);
    }
  }
}

struct DepthCase {
  std::string name;
  Shape a;
  Pose pa;
  Shape b;
  Pose pb;
  double depth;
};

const Eigen::Quaterniond kZToMinusX = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitX());
const Eigen::Quaterniond kZToX = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
const Eigen::Quaterniond kZToY = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY());

/// Closed-form depths of curved shapes at overlap `d` (shallow: 1e-6 .. deep: 5e-2).
std::vector<DepthCase> curved_depths(double d) {
  const Shape wall = Shape::box(0.5, 0.5, 0.5);
  const auto on_wall = [&](const std::string& name, const Shape& s, const Eigen::Quaterniond& r,
                           const Eigen::Vector3d& lateral) {
    // s pressed into the wall's +x face by d: its -x extreme sits at 0.5 - d, and x is the shortest way out.
    const double reach = testing::extent(s, r.inverse() * -Eigen::Vector3d::UnitX());
    return DepthCase{name, wall, Pose{}, s, Pose{Eigen::Vector3d(0.5 - d + reach, 0, 0) + lateral, r}, d};
  };
  return {
      {"sphere-sphere", Shape::sphere(0.1), Pose{}, Shape::sphere(0.15), Pose::from_translation({0.25 - d, 0.0, 0.0}), d},
      {"capsule-capsule parallel", Shape::capsule(0.05, 0.2), Pose{}, Shape::capsule(0.08, 0.1),
       Pose::from_translation({0.13 - d, 0.0, 0.05}), d},
      {"capsule-sphere", Shape::capsule(0.05, 0.2), Pose{}, Shape::sphere(0.07), Pose::from_translation({0.0, 0.12 - d, 0.1}), d},
      on_wall("wall-sphere", Shape::sphere(0.1), kIdentity, {0, 0.1, 0.2}),
      on_wall("wall-ellipsoid tip", Shape::ellipsoid(0.2, 0.05, 0.1), kIdentity, {0, -0.1, 0}),
      on_wall("wall-ellipsoid tilted", Shape::ellipsoid(0.2, 0.05, 0.1),
              Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())), {0, 0.1, 0}),
      on_wall("wall-cylinder cap", Shape::cylinder(0.1, 0.2), kZToX, {0, 0.1, 0}),
      on_wall("wall-cylinder rim", Shape::cylinder(0.1, 0.2), Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())), Eigen::Vector3d::Zero()),
      on_wall("wall-cone apex", Shape::cone(0.1, 0.2), kZToMinusX, Eigen::Vector3d::Zero()),
      on_wall("wall-cone base", Shape::cone(0.1, 0.2), kZToX, {0, 0.05, 0}),
      on_wall("wall-capsule side", Shape::capsule(0.05, 0.2), kZToY, {0, 0, -0.1}),
  };
}

/// Concentric pairs: the depth is the smallest width sum min_u (h_a(u) + h_b(-u)), attained on a common axis.
std::vector<DepthCase> concentric_depths() {
  const Pose centre{Eigen::Vector3d(0.2, -0.1, 0.3), Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))};
  return {
      {"ellipsoid-sphere concentric", Shape::ellipsoid(0.2, 0.05, 0.1), centre, Shape::sphere(0.03), centre, 0.08},
      {"ellipsoid-ellipsoid concentric", Shape::ellipsoid(0.2, 0.05, 0.1), centre, Shape::ellipsoid(0.1, 0.02, 0.3), centre, 0.07},
      {"cylinder-sphere concentric", Shape::cylinder(0.1, 0.04), centre, Shape::sphere(0.02), centre, 0.06},
      {"capsule-capsule crossed concentric", Shape::capsule(0.05, 0.2), centre, Shape::capsule(0.03, 0.2),
       Pose{centre.translation, centre.rotation * kZToX}, 0.08},
  };
}

void check_depths(const std::vector<DepthCase>& cases, Precision p, double double_tolerance, double bound, double& worst) {
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name + " depth " + std::to_string(c.depth) + " " + precision_name(p));
    const auto r = testing::run_pair(c.a, c.pa, c.b, c.pb, hard_case_options(p, QueryLevel::penetration, double_tolerance));
    expect_sane(r, QueryLevel::penetration, 4 * bound);
    EXPECT_TRUE(r.collide);
    EXPECT_LE(std::abs(r.distance + c.depth), bound);
    worst = std::max(worst, std::abs(r.distance + c.depth));
  }
}

TEST(HardCasesEpa, CurvedShapesShallowAndDeep) {
  for (Precision p : {Precision::float64, Precision::float32}) {
    // Double at EPA tolerance 1e-9: measured 2.3e-10 m, bound 1e-8. Float: measured 2.0e-7 m, bound 20 eps_f * 1 m.
    const double bound = p == Precision::float64 ? 1e-8 : 20 * kEpsFloat;
    double worst = 0.0;
    for (double d : {1e-6, 1e-4, 1e-2, 5e-2}) check_depths(curved_depths(d), p, 1e-9, bound, worst);
    check_depths(concentric_depths(), p, 1e-9, bound, worst);
    std::printf("[measured] EPA on curved shapes, depths 1e-6..0.08, %s: max |error| %.3g m (bound %.2g)\n", precision_name(p),
                worst, bound);
  }
}

}  // namespace
}  // namespace batchcol
