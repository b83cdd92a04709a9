#include "testkit/demo_scene.hpp"
#include "testkit/portable_random.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace batchcol::testkit {
namespace {

using Random = PortableRandom;

// Radii of balls centred at the shape's origin: `inner` lies inside the shape, `outer` contains it.
struct Bounds {
  double inner, outer;
};

// Dimensions (radii, half extents, half lengths) in [1 cm, 20 cm], i.e. sizes of 2-40 cm.
double dimension(Random& rng) { return rng.uniform(0.01, 0.2); }

Bounds add_primitive(ShapeTable& table, int kind, Random& rng) {
  const double r = dimension(rng), h = dimension(rng), c = dimension(rng);
  switch (kind) {
    case 0:
      table.add(Shape::sphere(r));
      return {r, r};
    case 1:
      table.add(Shape::capsule(r, h));
      return {r, r + h};
    case 2:
      table.add(Shape::box(r, h, c));
      return {std::min({r, h, c}), std::sqrt(r * r + h * h + c * c)};
    case 3:
      table.add(Shape::cylinder(r, h));
      return {std::min(r, h), std::hypot(r, h)};
    case 4:
      // Apex at +h, base of radius r at -h: the lateral surface is r*h/sqrt(4h^2 + r^2) from the origin.
      table.add(Shape::cone(r, h));
      return {std::min(h, r * h / std::sqrt(4.0 * h * h + r * r)), std::hypot(r, h)};
    default:
      table.add(Shape::ellipsoid(r, h, c));
      return {std::min({r, h, c}), std::max({r, h, c})};
  }
}

// 24 random points on a sphere of radius R plus the 6 axis points at 0.6 R: the hull contains their octahedron,
// hence the ball of radius 0.6 R / sqrt(3).
Bounds add_random_hull(ShapeTable& table, Random& rng) {
  const double radius = dimension(rng);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 24; ++i) points.push_back(radius * rng.unit_vector());
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) points.push_back(sign * 0.6 * radius * Eigen::Vector3d::Unit(axis));
  }
  table.add(Shape::convex(points));
  return {0.6 * radius / std::sqrt(3.0), radius};
}

// A box given as its 8 corners plus its edge midpoints (a polytope the hull code must simplify back to a box).
Bounds add_box_hull(ShapeTable& table, Random& rng) {
  Eigen::Vector3d half;
  for (int axis = 0; axis < 3; ++axis) half[axis] = dimension(rng);
  std::vector<Eigen::Vector3d> points;
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        if ((x != 0) + (y != 0) + (z != 0) >= 2) points.push_back(half.cwiseProduct(Eigen::Vector3d(x, y, z)));
      }
    }
  }
  table.add(Shape::convex(points));
  return {half.minCoeff(), half.norm()};
}

}  // namespace

DemoScene make_demo_scene(std::size_t pair_count, std::uint64_t seed) {
  // Every draw is its own statement: the evaluation order of function arguments is unspecified.
  Random rng(seed);
  DemoScene scene;
  std::vector<Bounds> bounds;
  constexpr int kPerPrimitive = 32, kPrimitiveKinds = 6, kRandomHulls = 4, kBoxHulls = 2;
  for (int kind = 0; kind < kPrimitiveKinds; ++kind) {
    for (int i = 0; i < kPerPrimitive; ++i) bounds.push_back(add_primitive(scene.shapes, kind, rng));
  }
  for (int i = 0; i < kRandomHulls; ++i) bounds.push_back(add_random_hull(scene.shapes, rng));
  for (int i = 0; i < kBoxHulls; ++i) bounds.push_back(add_box_hull(scene.shapes, rng));

  scene.pairs.reserve(pair_count);
  for (std::size_t i = 0; i < pair_count; ++i) {
    const auto a = static_cast<std::uint32_t>(rng.index(bounds.size()));
    const auto b = static_cast<std::uint32_t>(rng.index(bounds.size()));
    const bool overlap = i % 2 == 0;
    // Overlapping: the inner balls intersect. Separated: the outer balls are at least 2% of their radii apart.
    const double distance = overlap ? rng.uniform(0.0, 0.9) * (bounds[a].inner + bounds[b].inner)
                                    : rng.uniform(1.02, 1.5) * (bounds[a].outer + bounds[b].outer);
    Pose pose_a, pose_b;
    for (int axis = 0; axis < 3; ++axis) pose_a.translation[axis] = rng.uniform(-2.0, 2.0);
    pose_b.translation = pose_a.translation + distance * rng.unit_vector();
    pose_a.rotation = rng.rotation();
    pose_b.rotation = rng.rotation();
    scene.pairs.add(a, pose_a, b, pose_b);
    scene.overlapping += overlap ? 1 : 0;
  }
  return scene;
}

}  // namespace batchcol::testkit
